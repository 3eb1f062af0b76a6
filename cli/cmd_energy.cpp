// `fiberlab energy CONFIG_OR_RESULT [--models M,...] [--set KEY=VALUE ...]
//                 [--beta-sweep B,...] [--theta-i SPEC] [--run] [--report DIR]`
// Does model M conserve energy? Over the theta_i sweep of a result (or a
// config), the per-lobe and total energy of the simulation's ledger and of
// each model integrated over the sphere, and each one's departure from the
// white furnace (total - 1, for a white fiber). Given a config, only the
// models are evaluated unless --run is given (then the simulation runs here,
// in memory, with the config's photons or --photons).
#include <fmt/core.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "cli/commands.h"
#include "common/error.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "compare/comparison.h"
#include "compare/energy.h"
#include "compare/models.h"
#include "compare/report.h"
#include "sim/result_file.h"
#include "sim/settings.h"
#include "sim/simulation.h"

namespace fiberlab::cli {

namespace {

struct EnergyOptions {
  std::string input, models = "deon2011,marschner2003,marschner2003:longitudinal=two_theta_h";
  std::vector<std::string> settings;
  std::string beta_sweep, theta_i, report;
  bool run = false;
  long long photons = -1;
  int threads = 0, channel = 0, n_theta = 180, n_phi = 90;
};

std::vector<double> parse_degrees(const std::string& option, const std::string& text) {
  std::vector<double> out;
  const auto colon = text.find(':');
  try {
    if (colon != std::string::npos) {  // from:to:step
      std::vector<double> v;
      std::string part;
      std::istringstream in(text);
      while (std::getline(in, part, ':')) v.push_back(std::stod(part));
      if (v.size() != 3 || !(v[2] > 0) || v[1] < v[0]) throw std::invalid_argument("range");
      for (double x = v[0]; x <= v[1] + 1e-9 * v[2]; x += v[2]) out.push_back(deg_to_rad(x));
    } else {
      std::string part;
      std::istringstream in(text);
      while (std::getline(in, part, ','))
        if (!part.empty()) out.push_back(deg_to_rad(std::stod(part)));
    }
  } catch (const std::exception&) {
    throw Error(fmt::format("{} '{}': expected degrees A,B,C or FROM:TO:STEP", option, text));
  }
  if (out.empty()) throw Error(fmt::format("{} '{}': no values", option, text));
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

std::string curve_json(const compare::EnergyCurve& e, int c, int lobes_shown) {
  using compare::json_number;
  auto arr = [](const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += fmt::format("{}{}", s.empty() ? "" : ", ", json_number(x));
    return "[" + s + "]";
  };
  const std::size_t K = e.theta_i.size();
  std::vector<double> th, total, total_err, three, absorbed, truncated, ledger;
  std::string lobes = "[", errors = "[", names = "[";
  for (int l = 0; l < e.lobes; ++l) {
    std::vector<double> v, err;
    for (std::size_t k = 0; k < K; ++k) {
      v.push_back(e.at(k, l, c));
      err.push_back(e.error(k, l, c));
    }
    lobes += (l ? ", " : "") + arr(v);
    errors += (l ? ", " : "") + arr(err);
    names += fmt::format("{}\"{}\"", l ? ", " : "", compare::lobe_name(l, lobes_shown));
  }
  for (std::size_t k = 0; k < K; ++k) {
    th.push_back(rad_to_deg(e.theta_i[k]));
    total.push_back(e.total(k, c));
    total_err.push_back(e.total_error(k, c));
    three.push_back(e.three_lobe(k, c));
    if (e.simulated) {
      absorbed.push_back(e.absorbed[k * e.channels + c]);
      truncated.push_back(e.truncated[k * e.channels + c]);
      ledger.push_back(e.ledger[k * e.channels + c]);
    }
  }
  return fmt::format(
      "{{\"label\": {}, \"simulated\": {}, \"beta_long_deg\": {}, \"theta_i_deg\": {}, \"lobe_names\": {}], "
      "\"lobes\": {}], \"lobe_errors\": {}], \"total\": {}, \"total_error\": {}, \"three_lobe\": {}, "
      "\"absorbed\": {}, \"truncated\": {}, \"ledger\": {}}}",
      compare::json_string(e.label), e.simulated ? "true" : "false",
      e.beta_long >= 0 ? json_number(rad_to_deg(e.beta_long)) : std::string("null"), arr(th), names, lobes,
      errors, arr(total), arr(total_err), arr(three), arr(absorbed), arr(truncated), arr(ledger));
}

void energy_command(const EnergyOptions& o) {
  if (o.n_theta < 1 || o.n_phi < 1) throw Error("--grid: both sizes must be >= 1");
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
    if (o.photons == 0 || o.photons < -1) throw Error(fmt::format("--photons = {} must be >= 1", o.photons));
    if (o.photons > 0) settings.photons = static_cast<std::uint64_t>(o.photons);
    if (!o.theta_i.empty()) {
      if (o.run) throw Error("--theta-i cannot be combined with --run (edit the config's theta_i)");
      settings.source.theta_i = parse_degrees("--theta-i", o.theta_i);
    }
    if (o.run) {
      const sim::Simulation simulation(settings);
      result = sim::make_result(simulation.settings(), simulation.grid(), simulation.run(o.threads));
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
  if (!o.report.empty()) compare::make_report_dir(o.report);

  std::vector<compare::EnergyCurve> curves;
  if (simulated) curves.push_back(compare::simulation_energy(result));
  std::vector<double> betas;
  if (!o.beta_sweep.empty()) betas = parse_degrees("--beta-sweep", o.beta_sweep);
  for (const std::string& m : split_commas(o.models)) {
    const compare::ModelSpec spec = compare::parse_model_spec(m);
    const analytic::ModelParams base = compare::params_for(settings, spec, o.settings);
    auto add = [&](const analytic::ModelParams& p, const std::string& label, double beta) {
      const auto model = compare::make_model(spec.name, p);
      compare::EnergyCurve e = compare::model_energy(*model, label, theta_i, o.n_theta, o.n_phi);
      e.beta_long = beta;
      curves.push_back(std::move(e));
    };
    if (betas.empty()) add(base, spec.label, -1.0);
    for (double b : betas) {
      analytic::ModelParams p = base;
      p.beta_long = {b};
      add(p, fmt::format("{} beta_long={:g}", spec.label, rad_to_deg(b)), b);
    }
  }
  const int C = curves.empty() ? 0 : curves.front().channels;
  if (o.channel < 0 || o.channel >= C)
    throw Error(fmt::format("--channel {} out of range ({} channels)", o.channel, C));
  const int c = o.channel;

  fmt::print("{}: {}{}\n", o.input, from_result ? "result file" : "config",
             simulated ? (from_result ? "" : " (simulated here, --run)")
                       : " (simulation not run: models only; pass --run or a result file)");
  fmt::print("fiber: eta {:g}, sigma_a[{}] = {:g}{}; channel {} shown\n", settings.fiber.eta, c,
             settings.fiber.sigma_a.at(std::min<std::size_t>(c, settings.fiber.sigma_a.size() - 1)),
             white ? " (white: the furnace test applies, total should be 1)" : " (absorbing: no furnace test)",
             c);
  std::string csv = "source,beta_long_deg,theta_i_deg,channel";
  const int L = curves.front().lobes;
  for (int l = 0; l < L; ++l) csv += fmt::format(",{0},{0}_error", compare::lobe_name(l, L));
  csv += ",total,total_error,three_lobe,absorbed,truncated,ledger,furnace_departure\n";
  for (std::size_t k = 0; k < theta_i.size(); ++k) {
    fmt::print("\ntheta_i = {:.2f} deg\n  {:<44}", rad_to_deg(theta_i[k]), "source");
    for (int l = 0; l < L; ++l) fmt::print(" {:>9}", compare::lobe_name(l, L));
    fmt::print(" {:>9} {:>9} {:>10}{}\n", "total", "R+TT+TRT", white ? "total-1" : "",
               simulated ? "  absorbed truncated ledger" : "");
    for (const auto& e : curves) {
      fmt::print("  {:<44}", e.label.substr(0, 44));
      for (int l = 0; l < e.lobes; ++l) fmt::print(" {:9.6f}", e.at(k, l, c));
      const double total = e.total(k, c);
      fmt::print(" {:9.6f} {:9.6f} {:>10}", total, e.three_lobe(k, c),
                 white ? fmt::format("{:+.2e}", total - 1.0) : std::string());
      if (e.simulated)
        fmt::print("  {:8.6f} {:9.2e} {:.12f}  (total +- {:.1e})", e.absorbed[k * e.channels + c],
                   e.truncated[k * e.channels + c], e.ledger[k * e.channels + c], e.total_error(k, c));
      fmt::print("\n");
      for (int ch = 0; ch < e.channels; ++ch) {
        csv += fmt::format("\"{}\",{},{:.6g},{}", e.label, e.beta_long >= 0 ? fmt::format("{:g}", rad_to_deg(e.beta_long)) : "",
                           rad_to_deg(theta_i[k]), ch);
        for (int l = 0; l < e.lobes; ++l) csv += fmt::format(",{:.9g},{:.3g}", e.at(k, l, ch), e.error(k, l, ch));
        csv += fmt::format(",{:.9g},{:.3g},{:.9g}", e.total(k, ch), e.total_error(k, ch), e.three_lobe(k, ch));
        if (e.simulated)
          csv += fmt::format(",{:.9g},{:.3g},{:.15g}", e.absorbed[k * e.channels + ch],
                             e.truncated[k * e.channels + ch], e.ledger[k * e.channels + ch]);
        else
          csv += ",,,";
        csv += white ? fmt::format(",{:.6g}\n", e.total(k, ch) - 1.0) : std::string(",\n");
      }
    }
  }
  if (!o.report.empty()) {
    compare::write_text(o.report, "metrics.csv", csv);
    std::string js;
    for (const auto& e : curves) js += (js.empty() ? "\n    " : ",\n    ") + curve_json(e, c, L);
    compare::write_text(o.report, "metrics.json",
                        fmt::format("{{\n  \"kind\": \"energy\",\n  \"input\": {},\n  \"simulated\": {},\n"
                                    "  \"white\": {},\n  \"channel\": {},\n  \"curves\": [{}\n  ]\n}}\n",
                                    compare::json_string(o.input), simulated ? "true" : "false",
                                    white ? "true" : "false", c, js));
    const compare::PlotOutcome plots = compare::make_plots("energy", o.report);
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
    if (!plots.ran) md += plots.message + "\n\n";
    for (const std::string& png : plots.pngs) md += fmt::format("![{}]({})\n\n", png, png);
    md += "Numbers: `metrics.csv` (every channel), `metrics.json`.\n";
    compare::write_text(o.report, "report.md", md);
    fmt::print("\nreport: {}/report.md{}\n", o.report, plots.ran ? "" : " (" + plots.message + ")");
  }
}

}  // namespace

void add_energy_command(CLI::App& app) {
  auto o = std::make_shared<EnergyOptions>();
  CLI::App* cmd = app.add_subcommand(
      "energy", "Energy per lobe and in total over theta_i: simulation ledger vs models (white furnace)");
  cmd->add_option("input", o->input, "Result file (.h5) or YAML config (models only unless --run)")->required();
  cmd->add_option("--models", o->models,
                  "Comma-separated model specs NAME[:KEY=VALUE...] (default: deon2011, marschner2003, "
                  "marschner2003:longitudinal=two_theta_h)");
  cmd->add_option("--set", o->settings, "Model parameter KEY=VALUE for every model (degrees); repeatable");
  cmd->add_option("--beta-sweep", o->beta_sweep,
                  "Evaluate each model at these beta_long (degrees, every lobe), as in d'Eon 2011 Fig. 3");
  cmd->add_option("--theta-i", o->theta_i, "Config only: model theta_i, degrees A,B,C or FROM:TO:STEP");
  cmd->add_flag("--run", o->run, "Config only: run the simulation too (in memory)");
  cmd->add_option("--photons", o->photons, "With --run: photons per incident direction");
  cmd->add_option("--threads", o->threads, "With --run: OpenMP threads");
  cmd->add_option("--channel", o->channel, "Channel shown in the table and plots (0)");
  cmd->add_option("--grid-theta", o->n_theta, "theta bins of the models' integration grid (180)");
  cmd->add_option("--grid-phi", o->n_phi, "phi bins of the models' integration grid (90)");
  cmd->add_option("--report", o->report, "Write a report folder (report.md, metrics.csv/json, PNG plots)");
  cmd->callback([o] { energy_command(*o); });
}

}  // namespace fiberlab::cli
