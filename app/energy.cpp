#include "app/energy.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <optional>
#include <sstream>

#include "analytic/model_registry.h"
#include "app/run.h"
#include "app/threads.h"
#include "app/comma_list.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/interrupt.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "compare/energy_report.h"
#include "compare/models.h"
#include "compare/report.h"
#include "sim/run/memory_budget.h"
#include "sim/store/result_file.h"

namespace fiberlab::app {

namespace {

constexpr std::size_t kMaxSweep = 100000;  // as a config's theta_i range (configs/README.md)
constexpr int kMaxGridCells = 4000000;    // --grid-theta x --grid-phi

// An allowed interval of degrees, and how it is said in an error.
struct DegreeRange {
  double lo, hi;
  bool lo_open, hi_open;
  const char* text;
  bool contains(double x) const {
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
};
constexpr DegreeRange kThetaIRange{-90, 90, true, true, "each in (-90, 90) degrees"};
constexpr DegreeRange kBetaRange{0, 90, false, false, "each in [0, 90] degrees"};

// One finite number, the whole text (strtod alone accepts "95abc", "nan", "inf").
double parse_number(const std::string& option, const std::string& text, const std::string& part,
                    const char* rule) {
  char* end = nullptr;
  const double x = part.empty() ? NAN : std::strtod(part.c_str(), &end);
  if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(x))
    throw Error(fmt::format("command line: {} '{}': '{}' is not a finite number (expected degrees "
                            "A,B,C or FROM:TO:STEP, {})", option, text, part, rule));
  return x;
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, sep)) parts.push_back(part);
  return parts;
}

// The angles in degrees, checked against `range`.
std::vector<double> parse_degree_values(const std::string& option, const std::string& text,
                                        const DegreeRange& range) {
  const std::string usage = fmt::format("expected degrees A,B,C or FROM:TO:STEP, {}", range.text);
  std::vector<double> degrees;
  if (text.find(':') != std::string::npos) {
    const std::vector<std::string> p = split(text, ':');
    if (p.size() != 3)
      throw Error(fmt::format("command line: {} '{}': {}", option, text, usage));
    const double from = parse_number(option, text, p[0], range.text);
    const double to = parse_number(option, text, p[1], range.text);
    const double step = parse_number(option, text, p[2], range.text);
    if (!(step > 0) || to < from)
      throw Error(fmt::format("command line: {} '{}': needs FROM <= TO and STEP > 0", option, text));
    const double count = std::floor((to - from) / step + 1e-9) + 1.0;
    if (!(count <= static_cast<double>(kMaxSweep)))
      throw Error(fmt::format("command line: {} '{}' gives {:.3g} angles (at most {})", option, text,
                              count, kMaxSweep));
    for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i)
      degrees.push_back(std::min(from + static_cast<double>(i) * step, to));
  } else {
    for (const std::string& part : split(text, ','))
      if (!part.empty()) degrees.push_back(parse_number(option, text, part, range.text));
    if (degrees.size() > kMaxSweep)
      throw Error(fmt::format("command line: {} gives {} angles (at most {})", option,
                              degrees.size(), kMaxSweep));
  }
  if (degrees.empty()) throw Error(fmt::format("command line: {} '{}': no values ({})", option, text, usage));
  for (double d : degrees)
    if (!range.contains(d))
      throw Error(fmt::format("command line: {} '{}': {} is out of range ({})", option, text, d,
                              range.text));
  return degrees;
}

// The same angles in radians.
std::vector<double> parse_degrees(const std::string& option, const std::string& text,
                                  const DegreeRange& range) {
  std::vector<double> out;
  for (double d : parse_degree_values(option, text, range)) out.push_back(deg_to_rad(d));
  return out;
}

}  // namespace

// The models `energy` evaluates when --models is not given: every registered
// model, each at its default quadrature (huang2022's costs seconds per
// theta_i).
std::string energy_models_help() {
  return fmt::format(
      "Comma-separated model specs NAME[:KEY=VALUE...] (default: every registered model: {}; a "
      "model that does not apply to the fiber, such as a circular-only one on an ellipse, is listed and "
      "skipped; huang2022 takes seconds per theta_i at its default quadrature_points, so a long sweep "
      "may want huang2022:quadrature_points=262144 or leaving it out)",
      fmt::join(analytic::model_names(), ", "));
}

namespace {

// Does model `name`'s table have the key of KEY=VALUE?
bool has_key(const std::string& name, const std::string& key_value) {
  const std::string key = key_value.substr(0, key_value.find('='));
  return analytic::find_param(analytic::model_info(name).params, key) != nullptr;
}

}  // namespace

EnergyResult energy(const EnergyRequest& o) {
  if (o.n_theta < 1 || o.n_phi < 1 || o.n_theta > kMaxGridCells / o.n_phi)
    throw Error(fmt::format("command line: --grid-theta = {} x --grid-phi = {} is out of range (each "
                            ">= 1, product at most {})", o.n_theta, o.n_phi, kMaxGridCells));
  const bool from_result = is_hdf5_file(o.input);
  sim::ResultFile result;
  sim::Settings settings;
  bool simulated = false;
  if (from_result) {
    if (o.run) throw Error("--run needs a config, not a result file");
    if (!o.theta_i.empty()) throw Error("--theta-i applies to configs only (a result fixes theta_i)");
    result = sim::read_result(o.input);
    settings = result.settings;
    simulated = true;
  } else {
    settings = sim::load_settings(o.input);
    if (o.photons_given)
      settings.photons = sim::parse_integer_flag("--photons", o.photons, 1, ~std::uint64_t{0});
    if (!o.theta_i.empty()) {
      if (o.run) throw Error("--theta-i cannot be combined with --run (edit the config's theta_i)");
      settings.source.theta_i = parse_degrees("--theta-i", o.theta_i, kThetaIRange);
    }
    if (o.run) {
      const int threads =
          o.threads.empty() ? run_threads(0)
                            : static_cast<int>(sim::parse_integer_flag("--threads", o.threads, 1, sim::kMaxThreads));
      std::optional<sim::ResultFile> done = simulate(settings, threads);
      if (!done) throw Error(fmt::format("interrupted by signal {}", interrupt_signal()));
      result = std::move(*done);
      simulated = true;
    }
  }
  std::vector<double> theta_i;
  if (simulated) theta_i = result.theta_i;
  else
    for (const auto& inc : settings.incidences())
      if (theta_i.empty() || theta_i.back() != inc.theta_i) theta_i.push_back(inc.theta_i);
  bool white = true;
  for (double s : settings.fiber.sigma_a) white = white && s == 0.0;
  if (settings.fiber.medulla)
    for (double s : settings.fiber.medulla->sigma_a) white = white && s == 0.0;
  const bool every_model = o.models.empty();
  const std::vector<std::string> model_specs = every_model ? analytic::model_names() : split_commas(o.models);
  // --set KEY=VALUE goes to every model whose table has KEY; a key no model has is an error.
  for (const std::string& kv : o.settings) {
    bool used = false;
    for (const std::string& m : model_specs) used = used || has_key(compare::parse_model_spec(m).name, kv);
    if (!used)
      throw Error(fmt::format("--set {}: no model of --models {} has this key (`fiberlab models` lists them)", kv,
                              every_model ? "(every model)" : o.models));
  }
  if (!o.report.empty()) compare::make_report_dir(o.report);

  std::vector<compare::EnergyCurve> curves;
  if (simulated) curves.push_back(compare::simulation_energy(result));
  std::vector<double> betas;  // degrees, as the parameter table takes them
  if (!o.beta_sweep.empty()) betas = parse_degree_values("--beta-sweep", o.beta_sweep, kBetaRange);
  std::vector<std::string> skipped;
  for (const std::string& m : model_specs) {
    const compare::ModelSpec spec = compare::parse_model_spec(m);
    std::vector<std::string> sets;
    for (const std::string& kv : o.settings)
      if (has_key(spec.name, kv)) sets.push_back(kv);
    analytic::ModelParameters base;
    std::unique_ptr<analytic::Model> model;
    try {
      base = compare::params_for(settings, spec, sets);
      model = compare::make_model(spec.name, base);
    } catch (const Error& e) {
      if (!every_model) throw;
      skipped.push_back(fmt::format("{}: not applicable: {}", spec.name, e.what()));
      continue;
    }
    auto add = [&](const analytic::Model& m, const std::string& label, double beta) {
      compare::EnergyCurve e = compare::model_energy(m, label, theta_i, o.n_theta, o.n_phi);
      e.beta_long = beta;
      curves.push_back(std::move(e));
    };
    // --beta-sweep varies the models that have a beta_long; the others are evaluated once.
    if (betas.empty() || !has_key(spec.name, "beta_long")) {
      add(*model, spec.label, -1.0);
      continue;
    }
    const analytic::ParamSpec& beta_long = *analytic::find_param(analytic::model_info(spec.name).params, "beta_long");
    for (double degrees : betas) {
      analytic::ModelParameters p = base;
      beta_long.set_entry(p, -1, degrees);  // one width for every lobe
      const double b = deg_to_rad(degrees);
      add(*compare::make_model(spec.name, p), fmt::format("{} beta_long={:g}", spec.label, rad_to_deg(b)), b);
    }
  }
  if (curves.empty()) throw Error(fmt::format("energy {}: no model applies to this fiber ({})", o.input,
                                              fmt::join(skipped, "; ")));
  // A fiber with a medulla: its lobe `scattered`, which no model has (docs/FUR.md).
  if (settings.fiber.medulla)
    for (auto& e : curves)
      if (!e.simulated) compare::add_scattered_lobe(e);
  const int C = curves.empty() ? 0 : curves.front().channels;
  if (o.channel < 0 || o.channel >= C)
    throw Error(fmt::format("--channel {} out of range ({} channels)", o.channel, C));

  EnergyResult out;
  out.from_result = from_result;
  out.simulated = simulated;
  out.white = white;
  out.settings = std::move(settings);
  out.theta_i = std::move(theta_i);
  out.curves = std::move(curves);
  out.skipped = std::move(skipped);
  out.lobe_names = lobe_names(out.curves.front().lobes, out.settings.fiber.medulla.has_value());
  return out;
}

std::string write_energy_report(const EnergyRequest& o, const EnergyResult& r) {
  compare::EnergyReport report;
  report.dir = o.report;
  report.input = o.input;
  report.simulated = r.simulated;
  report.white = r.white;
  report.channel = o.channel;
  report.n_theta = o.n_theta;
  report.n_phi = o.n_phi;
  report.theta_i = r.theta_i;
  report.lobe_names = r.lobe_names;
  return compare::write_energy_report(report, r.curves);
}

}  // namespace fiberlab::app

