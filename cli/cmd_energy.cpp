// `fiberlab energy CONFIG_OR_RESULT [--models M,...] [--set KEY=VALUE ...]
//                 [--beta-sweep B,...] [--theta-i SPEC] [--run] [--report DIR]`
// Does model M conserve energy? Over the theta_i sweep of a result (or a
// config), the per-lobe and total energy of the simulation's ledger and of
// each model integrated over the sphere, and each one's departure from the
// white furnace (total - 1, for a white fiber). Given a config, only the
// models are evaluated unless --run is given (then the simulation runs here,
// in memory, with the config's photons or --photons).
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>

#include "analytic/model_registry.h"
#include "cli/commands.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "compare/comparison.h"
#include "compare/energy.h"
#include "compare/models.h"
#include "compare/report.h"
#include "compare/report_folder.h"
#include "sim/run/memory_budget.h"
#include "sim/store/result_file.h"
#include "sim/run/settings.h"
#include "sim/run/simulation.h"

namespace fiberlab::cli {

namespace {

struct EnergyOptions {
  std::string input, models;  // empty: every registered model (energy_models_help)
  std::vector<std::string> settings;
  std::string beta_sweep, theta_i, report;
  bool run = false;
  std::string photons, threads;  // checked by sim::parse_integer_flag
  int channel = 0, n_theta = 180, n_phi = 90;
};

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

std::vector<double> parse_degrees(const std::string& option, const std::string& text,
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
  std::vector<double> out;
  for (double d : degrees) {
    if (!range.contains(d))
      throw Error(fmt::format("command line: {} '{}': {} is out of range ({})", option, text, d,
                              range.text));
    out.push_back(deg_to_rad(d));
  }
  return out;
}

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, ','))
    if (!part.empty()) out.push_back(part);
  return out;
}

// The models `energy` evaluates when --models is not given: every registered
// model, each at its default quadrature (huang2022's costs seconds per
// theta_i: see energy_models_help).
std::string energy_models_help() {
  return fmt::format(
      "Comma-separated model specs NAME[:KEY=VALUE...] (default: every registered model: {}; a "
      "model that does not apply to the fiber, such as a circular-only one on an ellipse, is listed and "
      "skipped; huang2022 takes seconds per theta_i at its default quadrature_points, so a long sweep "
      "may want huang2022:quadrature_points=262144 or leaving it out)",
      fmt::join(analytic::model_names(), ", "));
}

// Does model `name`'s table have the key of KEY=VALUE?
bool has_key(const std::string& name, const std::string& key_value) {
  const std::string key = key_value.substr(0, key_value.find('='));
  return analytic::find_param(analytic::model_info(name).params, key) != nullptr;
}

std::string curve_json(const compare::EnergyCurve& e, int c, const std::vector<std::string>& lobe_names) {
  using compare::json_number;
  auto arr = [](const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += fmt::format("{}{}", s.empty() ? "" : ", ", json_number(x));
    return "[" + s + "]";
  };
  const std::size_t K = e.theta_i.size();
  std::vector<double> th, total, total_err, three, absorbed, truncated, lost, ledger;
  std::string lobes = "[", errors = "[", names = "[";
  for (int l = 0; l < e.lobes; ++l) {
    std::vector<double> v, err;
    for (std::size_t k = 0; k < K; ++k) {
      v.push_back(e.at(k, l, c));
      err.push_back(e.error(k, l, c));
    }
    lobes += (l ? ", " : "") + arr(v);
    errors += (l ? ", " : "") + arr(err);
    names += fmt::format("{}\"{}\"", l ? ", " : "", lobe_names.at(l));
  }
  for (std::size_t k = 0; k < K; ++k) {
    th.push_back(rad_to_deg(e.theta_i[k]));
    total.push_back(e.total(k, c));
    total_err.push_back(e.total_error(k, c));
    three.push_back(e.three_lobe(k, c));
    if (e.simulated) {
      absorbed.push_back(e.absorbed[k * e.channels + c]);
      truncated.push_back(e.truncated[k * e.channels + c]);
      lost.push_back(e.lost[k * e.channels + c]);
      ledger.push_back(e.ledger[k * e.channels + c]);
    }
  }
  return fmt::format(
      "{{\"label\": {}, \"simulated\": {}, \"beta_long_deg\": {}, \"theta_i_deg\": {}, \"lobe_names\": {}], "
      "\"lobes\": {}], \"lobe_errors\": {}], \"total\": {}, \"total_error\": {}, \"three_lobe\": {}, "
      "\"absorbed\": {}, \"truncated\": {}, \"lost\": {}, \"ledger\": {}}}",
      compare::json_string(e.label), e.simulated ? "true" : "false",
      e.beta_long >= 0 ? json_number(rad_to_deg(e.beta_long)) : std::string("null"), arr(th), names, lobes,
      errors, arr(total), arr(total_err), arr(three), arr(absorbed), arr(truncated), arr(lost), arr(ledger));
}

void energy_command(const EnergyOptions& o, bool photons_given) {
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
    if (photons_given)
      settings.photons = sim::parse_integer_flag("--photons", o.photons, 1, ~std::uint64_t{0});
    if (!o.theta_i.empty()) {
      if (o.run) throw Error("--theta-i cannot be combined with --run (edit the config's theta_i)");
      settings.source.theta_i = parse_degrees("--theta-i", o.theta_i, kThetaIRange);
    }
    if (o.run) {
      const int threads =
          o.threads.empty() ? std::min(omp_get_max_threads(), sim::kMaxThreads)
                            : static_cast<int>(sim::parse_integer_flag("--threads", o.threads, 1, sim::kMaxThreads));
      sim::check_memory_budget(settings, threads);
      const sim::Simulation simulation(settings);
      result = sim::make_result(simulation.settings(), simulation.grid(), simulation.run(threads));
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
  std::vector<double> betas;
  if (!o.beta_sweep.empty()) betas = parse_degrees("--beta-sweep", o.beta_sweep, kBetaRange);
  std::vector<std::string> skipped;
  for (const std::string& m : model_specs) {
    const compare::ModelSpec spec = compare::parse_model_spec(m);
    std::vector<std::string> sets;
    for (const std::string& kv : o.settings)
      if (has_key(spec.name, kv)) sets.push_back(kv);
    analytic::ModelParams base;
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
    for (double b : betas) {
      analytic::ModelParams p = base;
      p.beta_long = {b};
      add(*compare::make_model(spec.name, p), fmt::format("{} beta_long={:g}", spec.label, rad_to_deg(b)), b);
    }
  }
  if (curves.empty()) throw Error(fmt::format("energy {}: no model applies to this fiber ({})", o.input,
                                              fmt::join(skipped, "; ")));
  const int C = curves.empty() ? 0 : curves.front().channels;
  if (o.channel < 0 || o.channel >= C)
    throw Error(fmt::format("--channel {} out of range ({} channels)", o.channel, C));
  const int c = o.channel;

  fmt::print("{}: {}{}\n", o.input, from_result ? "result file" : "config",
             simulated ? (from_result ? "" : " (simulated here, --run)")
                       : " (simulation not run: models only; pass --run or a result file)");
  for (const std::string& line : skipped) fmt::print("{}\n", line);
  fmt::print("fiber: eta {:g}, sigma_a[{}] = {:g}{}; channel {} shown\n", settings.fiber.eta, c,
             settings.fiber.sigma_a.at(std::min<std::size_t>(c, settings.fiber.sigma_a.size() - 1)),
             white ? " (white: the furnace test applies, total should be 1)" : " (absorbing: no furnace test)",
             c);
  std::string csv = "source,beta_long_deg,theta_i_deg,channel";
  // A fiber with a medulla: its lobe `scattered`, which no model has (docs/FUR.md).
  if (settings.fiber.medulla)
    for (auto& e : curves)
      if (!e.simulated) compare::add_scattered_lobe(e);
  const int L = curves.front().lobes;
  const std::vector<std::string> names = lobe_names(L, settings.fiber.medulla.has_value());
  for (int l = 0; l < L; ++l) csv += fmt::format(",{0},{0}_error", names[l]);
  csv += ",total,total_error,three_lobe,absorbed,truncated,lost,ledger,furnace_departure\n";
  for (std::size_t k = 0; k < theta_i.size(); ++k) {
    fmt::print("\ntheta_i = {:.2f} deg\n  {:<44}", rad_to_deg(theta_i[k]), "source");
    for (int l = 0; l < L; ++l) fmt::print(" {:>9}", names[l]);
    fmt::print(" {:>9} {:>9} {:>10}{}\n", "total", "R+TT+TRT", white ? "total-1" : "",
               simulated ? "  absorbed truncated      lost ledger" : "");
    for (const auto& e : curves) {
      fmt::print("  {:<44}", e.label.substr(0, 44));
      for (int l = 0; l < e.lobes; ++l) fmt::print(" {:9.6f}", e.at(k, l, c));
      const double total = e.total(k, c);
      fmt::print(" {:9.6f} {:9.6f} {:>10}", total, e.three_lobe(k, c),
                 white ? fmt::format("{:+.2e}", total - 1.0) : std::string());
      if (e.simulated)
        fmt::print("  {:8.6f} {:9.2e} {:9.6f} {:.12f}  (total +- {:.1e})", e.absorbed[k * e.channels + c],
                   e.truncated[k * e.channels + c], e.lost[k * e.channels + c],
                   e.ledger[k * e.channels + c], e.total_error(k, c));
      fmt::print("\n");
      for (int ch = 0; ch < e.channels; ++ch) {
        csv += fmt::format("\"{}\",{},{:.6g},{}", e.label, e.beta_long >= 0 ? fmt::format("{:g}", rad_to_deg(e.beta_long)) : "",
                           rad_to_deg(theta_i[k]), ch);
        for (int l = 0; l < e.lobes; ++l) csv += fmt::format(",{:.9g},{:.3g}", e.at(k, l, ch), e.error(k, l, ch));
        csv += fmt::format(",{:.9g},{:.3g},{:.9g}", e.total(k, ch), e.total_error(k, ch), e.three_lobe(k, ch));
        if (e.simulated)
          csv += fmt::format(",{:.9g},{:.3g},{:.9g},{:.15g}", e.absorbed[k * e.channels + ch],
                             e.truncated[k * e.channels + ch], e.lost[k * e.channels + ch],
                             e.ledger[k * e.channels + ch]);
        else
          csv += ",,,,";
        csv += white ? fmt::format(",{:.6g}\n", e.total(k, ch) - 1.0) : std::string(",\n");
      }
    }
  }
  if (!o.report.empty()) {
    compare::ReportFolder folder(o.report);
    try {
      const std::string& dir = folder.staging();
      compare::write_text(dir, "metrics.csv", csv);
      std::string js;
      for (const auto& e : curves) js += (js.empty() ? "\n    " : ",\n    ") + curve_json(e, c, names);
      compare::write_text(dir, "metrics.json",
                          fmt::format("{{\n  \"kind\": \"energy\",\n  \"input\": {},\n  \"simulated\": {},\n"
                                      "  \"white\": {},\n  \"channel\": {},\n  \"curves\": [{}\n  ]\n}}\n",
                                      compare::json_string(o.input), simulated ? "true" : "false",
                                      white ? "true" : "false", c, js));
      const compare::PlotOutcome plots = compare::make_plots("energy", dir);
      std::string md = fmt::format("# Energy: {}\n\n{}. Channel {}. Models integrated over the sphere on a "
                                   "{} x {} grid (sum of bin probabilities).\n\n",
                                   o.input,
                                   simulated ? "Simulated and predicted" : "Models only (the simulation was not run)",
                                   c, o.n_theta, o.n_phi);
      md += "| source | theta_i | total | R+TT+TRT |" + std::string(white ? " total - 1 |" : "") +
            "\n|---|---|---|---|" + (white ? "---|" : "") + "\n";
      for (const auto& e : curves)
        for (std::size_t k = 0; k < theta_i.size(); ++k)
          md += fmt::format("| {} | {:.1f} | {:.5f} | {:.5f} |{}\n", e.label, rad_to_deg(theta_i[k]), e.total(k, c),
                            e.three_lobe(k, c), white ? fmt::format(" {:+.4f} |", e.total(k, c) - 1.0) : "");
      md += "\n## Plots\n\n";
      if (plots.html) md += "All figures on one page: [report.html](report.html).\n\n";
      if (!plots.ran) md += plots.message + "\n\n";
      for (const std::string& png : plots.pngs) md += fmt::format("![{}]({})\n\n", png, png);
      md += "Numbers: `metrics.csv` (every channel), `metrics.json`.\n";
      compare::write_text(dir, "report.md", md);
      folder.commit();
      fmt::print("\nreport: {}/report.md{}{}\n", o.report,
                 plots.html ? fmt::format(", {}/report.html", o.report) : "",
                 plots.ran ? "" : " (" + plots.message + ")");
    } catch (const std::exception& e) {
      folder.rethrow(e);
    }
  }
}

}  // namespace

void add_energy_command(CLI::App& app) {
  auto o = std::make_shared<EnergyOptions>();
  CLI::App* cmd = app.add_subcommand(
      "energy", "Energy per lobe and in total over theta_i: simulation ledger vs models (white furnace)");
  cmd->add_option("input", o->input, "Result file (.h5) or YAML config (models only unless --run)")->required();
  cmd->add_option("--models", o->models, energy_models_help());
  cmd->add_option("--set", o->settings,
                  "Model parameter KEY=VALUE for every model that has KEY (degrees); repeatable");
  cmd->add_option("--beta-sweep", o->beta_sweep,
                  "Evaluate each model that has beta_long at these beta_long (degrees, every lobe), as in "
                  "d'Eon 2011 Fig. 3");
  cmd->add_option("--theta-i", o->theta_i, "Config only: model theta_i, degrees A,B,C or FROM:TO:STEP");
  cmd->add_flag("--run", o->run, "Config only: run the simulation too (in memory)");
  CLI::Option* photons = cmd->add_option("--photons", o->photons, "With --run: photons per incident direction");
  cmd->add_option("--threads", o->threads, "With --run: OpenMP threads");
  cmd->add_option("--channel", o->channel, "Channel shown in the table and plots (0)");
  cmd->add_option("--grid-theta", o->n_theta, "theta bins of the models' integration grid (180)");
  cmd->add_option("--grid-phi", o->n_phi, "phi bins of the models' integration grid (90)");
  cmd->add_option("--report", o->report, "Write a report folder (report.md, metrics.csv/json, PNG plots)");
  cmd->callback([o, photons] { energy_command(*o, photons->count() > 0); });
}

}  // namespace fiberlab::cli
