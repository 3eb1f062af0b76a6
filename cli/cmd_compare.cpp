// `fiberlab compare RESULT.h5 --model M [--set KEY=VALUE ...] [--fit KEYS]
//                  [--report DIR] [--max-chi2 X]`
// Is model M right for the fiber of RESULT, where, and by how much?
// Exit status 0 when every judged lobe is accepted, 1 when one is not, 2 on
// bad input. See compare/comparison.h for the statistics.
#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "cli/commands.h"
#include "common/error.h"
#include "common/units.h"
#include "compare/comparison.h"
#include "compare/fit.h"
#include "compare/models.h"
#include "compare/report.h"
#include "sim/result_file.h"

namespace fiberlab::cli {

namespace {

struct CompareOptions {
  std::string result, model, fit, report;
  std::vector<std::string> settings;
  // <= 0: per lobe, 1 + 5 sqrt(2 / dof) (five standard deviations of
  // chi2/dof above its mean for a correct model, SPEC s10).
  double max_chi2 = 0.0;
  double min_effective = 30.0, model_error = 1e-4, min_energy = 1e-4;
  int channel = 0;
};

double threshold(const CompareOptions& o, int dof) {
  return o.max_chi2 > 0.0 ? o.max_chi2 : 1.0 + 5.0 * std::sqrt(2.0 / std::max(dof, 1));
}

std::string degrees_list(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += fmt::format("{}{:g}", s.empty() ? "" : ",", rad_to_deg(x));
  return s;
}

std::string describe(const analytic::ModelParams& p) {
  std::string sa;
  for (double x : p.sigma_a) sa += fmt::format("{}{:g}", sa.empty() ? "" : ",", x);
  return fmt::format("eta={:g} sigma_a={} beta_long={} beta_azim={} alpha={} absorption={} lobes={}",
                     p.eta, sa, degrees_list(p.beta_long), degrees_list(p.beta_azim),
                     degrees_list(p.alpha),
                     p.absorption == analytic::Absorption::Chord ? "chord" : "published", p.lobes);
}

std::string params_json(const analytic::ModelParams& p) {
  auto list = [](const std::vector<double>& v, double scale) {
    std::string s;
    for (double x : v) s += fmt::format("{}{}", s.empty() ? "" : ", ", compare::json_number(x * scale));
    return "[" + s + "]";
  };
  const double d = 180.0 / kPi;
  return fmt::format(
      "{{\"eta\": {}, \"sigma_a\": {}, \"beta_long_deg\": {}, \"beta_azim_deg\": {}, \"alpha_deg\": {}, "
      "\"absorption\": \"{}\", \"lobes\": {}}}",
      compare::json_number(p.eta), list(p.sigma_a, 1.0), list(p.beta_long, d), list(p.beta_azim, d),
      list(p.alpha, d), p.absorption == analytic::Absorption::Chord ? "chord" : "published", p.lobes);
}

struct Judged {
  std::vector<compare::LobeComparison> rows;
  std::vector<bool> accepted;
  bool all = true;
  int judged = 0;
};

Judged judge(std::vector<compare::LobeComparison> rows, const CompareOptions& o) {
  Judged j;
  j.rows = std::move(rows);
  for (const auto& r : j.rows) {
    const bool ok = !r.judged || r.bins.per_dof() <= threshold(o, r.bins.dof);
    j.accepted.push_back(ok);
    if (r.judged) ++j.judged;
    j.all = j.all && ok;
  }
  return j;
}

void print_table(const Judged& j, int lobes) {
  fmt::print("{:>7} {:>5} {:>2} {:>21} {:>10} {:>7} {:>10} {:>5} {:>8} {:>8} {:>6} {:>8} {:>8} {:>8}  {}\n",
             "theta_i", "lobe", "c", "E_sim +- se", "E_model", "z", "chi2/dof", "dof", "theta", "phi",
             "L1", "cen_sim", "cen_mod", "shift", "verdict");
  for (std::size_t i = 0; i < j.rows.size(); ++i) {
    const auto& r = j.rows[i];
    fmt::print("{:7.2f} {:>5} {:>2} {:>21} {:10.6f} {:7.1f} {:10.3f} {:5d} {:8.3f} {:8.3f} {:6.3f} {:8.3f} {:8.3f} {:8.3f}  {}\n",
               rad_to_deg(r.theta_i), compare::lobe_name(r.lobe, lobes), r.channel,
               fmt::format("{:.6f} +- {:.6f}", r.sim_energy, r.sim_error), r.model_energy, r.energy_z,
               r.bins.per_dof(), r.bins.dof, r.theta_marginal.per_dof(), r.phi_marginal.per_dof(), r.l1,
               rad_to_deg(r.centroid_sim), rad_to_deg(r.centroid_model), rad_to_deg(r.measured_shift),
               !r.judged ? "not judged" : (j.accepted[i] ? "ok" : "REJECTED"));
  }
}

std::string metrics_csv(const Judged& j, int lobes, const CompareOptions& o) {
  std::string s =
      "theta_i_deg,phi_i_deg,lobe,lobe_name,channel,sim_energy,sim_error,model_energy,energy_z,chi2,dof,"
      "chi2_per_dof,compared_bins,rest_sim,rest_model,theta_chi2_per_dof,theta_dof,phi_chi2_per_dof,"
      "phi_dof,l1,peak_sim_deg,peak_model_deg,centroid_sim_deg,centroid_sim_error_deg,"
      "centroid_model_deg,alpha_model_deg,measured_shift_deg,judged,threshold,accepted\n";
  for (std::size_t i = 0; i < j.rows.size(); ++i) {
    const auto& r = j.rows[i];
    s += fmt::format("{:.6g},{:.6g},{},{},{},{:.9g},{:.3g},{:.9g},{:.4g},{:.6g},{},{:.6g},{},{:.6g},{:.6g},"
                     "{:.6g},{},{:.6g},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.4g},{:.6g},{:.6g},{:.6g},{},{:.4g},{}\n",
                     rad_to_deg(r.theta_i), rad_to_deg(r.phi_i), r.lobe, compare::lobe_name(r.lobe, lobes),
                     r.channel, r.sim_energy, r.sim_error, r.model_energy, r.energy_z, r.bins.chi2,
                     r.bins.dof, r.bins.per_dof(), r.compared_bins, r.rest_sim, r.rest_model,
                     r.theta_marginal.per_dof(), r.theta_marginal.dof, r.phi_marginal.per_dof(),
                     r.phi_marginal.dof, r.l1, rad_to_deg(r.peak_sim), rad_to_deg(r.peak_model),
                     rad_to_deg(r.centroid_sim), rad_to_deg(r.centroid_sim_error),
                     rad_to_deg(r.centroid_model), rad_to_deg(r.alpha_model),
                     rad_to_deg(r.measured_shift), r.judged ? 1 : 0, threshold(o, r.bins.dof),
                     j.accepted[i] ? 1 : 0);
  }
  return s;
}

std::string rows_json(const Judged& j, int lobes, const CompareOptions& o) {
  using compare::json_number;
  std::string s = "[";
  for (std::size_t i = 0; i < j.rows.size(); ++i) {
    const auto& r = j.rows[i];
    s += fmt::format(
        "{}\n    {{\"theta_i_deg\": {}, \"phi_i_deg\": {}, \"k\": {}, \"lobe\": {}, \"lobe_name\": \"{}\", "
        "\"channel\": {}, \"sim_energy\": {}, \"sim_error\": {}, \"model_energy\": {}, \"energy_z\": {}, "
        "\"chi2\": {}, \"dof\": {}, \"chi2_per_dof\": {}, \"theta_marginal_chi2_per_dof\": {}, "
        "\"theta_marginal_dof\": {}, \"phi_marginal_chi2_per_dof\": {}, \"phi_marginal_dof\": {}, "
        "\"l1\": {}, \"peak_sim_deg\": {}, \"peak_model_deg\": {}, \"centroid_sim_deg\": {}, "
        "\"centroid_sim_error_deg\": {}, \"centroid_model_deg\": {}, \"alpha_model_deg\": {}, "
        "\"measured_shift_deg\": {}, \"judged\": {}, \"threshold\": {}, \"accepted\": {}}}",
        i ? "," : "", json_number(rad_to_deg(r.theta_i)), json_number(rad_to_deg(r.phi_i)), r.k, r.lobe,
        compare::lobe_name(r.lobe, lobes), r.channel, json_number(r.sim_energy), json_number(r.sim_error),
        json_number(r.model_energy), json_number(r.energy_z), json_number(r.bins.chi2), r.bins.dof,
        json_number(r.bins.per_dof()), json_number(r.theta_marginal.per_dof()), r.theta_marginal.dof,
        json_number(r.phi_marginal.per_dof()), r.phi_marginal.dof, json_number(r.l1),
        json_number(rad_to_deg(r.peak_sim)), json_number(rad_to_deg(r.peak_model)),
        json_number(rad_to_deg(r.centroid_sim)), json_number(rad_to_deg(r.centroid_sim_error)),
        json_number(rad_to_deg(r.centroid_model)), json_number(rad_to_deg(r.alpha_model)),
        json_number(rad_to_deg(r.measured_shift)), r.judged ? "true" : "false",
        json_number(threshold(o, r.bins.dof)), j.accepted[i] ? "true" : "false");
  }
  return s + "\n  ]";
}

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, ','))
    if (!part.empty()) out.push_back(part);
  return out;
}

void compare_command(const CompareOptions& o) {
  if (o.max_chi2 < 0.0) throw Error(fmt::format("--max-chi2 = {} must be > 0", o.max_chi2));
  if (!(o.min_effective > 0.0)) throw Error("--min-effective must be > 0");
  const sim::ResultFile result = sim::read_result(o.result);
  if (o.channel < 0 || o.channel >= result.channels)
    throw Error(fmt::format("--channel {} out of range (the result has {} channels)", o.channel, result.channels));
  const compare::ModelSpec spec = compare::parse_model_spec(o.model);
  analytic::ModelParams params = compare::params_for(result.settings, spec, o.settings);
  compare::Options copt;
  copt.min_effective = o.min_effective;
  copt.model_rel_error = o.model_error;
  copt.min_lobe_energy = o.min_energy;
  if (!o.report.empty()) compare::make_report_dir(o.report);

  const auto t0 = std::chrono::steady_clock::now();
  fmt::print("{}: {} incident direction(s), {} lobes, {} channel(s), {} x {} bins\n", o.result,
             result.configs(), result.lobes, result.channels, result.grid.n_theta(), result.grid.n_phi());
  fmt::print("model {}: {}\n", spec.label, describe(params));
  auto model = compare::make_model(spec.name, params);
  auto bins = compare::predict_result(*model, result);
  Judged j = judge(compare::compare(result, bins, params.alpha, copt), o);
  print_table(j, result.lobes);

  std::string fit_json = "null", fit_md;
  if (!o.fit.empty()) {
    const std::vector<std::string> keys = split_commas(o.fit);
    const compare::FitResult fr = compare::fit_model(result, spec.name, params, keys, copt);
    fmt::print("\nfit of {} ({} residuals, {} iterations, {} model evaluations{}):\n", o.fit, fr.residuals,
               fr.iterations, fr.evaluations, fr.converged ? "" : ", NOT converged");
    fmt::print("  chi2/dof {:.4f} -> {:.4f} (dof {}); errors scaled by sqrt(max(1, chi2/dof)) = {:.3f}\n",
               fr.chi2_start / fr.dof, fr.per_dof(), fr.dof, std::sqrt(std::max(1.0, fr.per_dof())));
    fit_md = fmt::format("## Fit\n\nchi2/dof {:.4f} -> {:.4f} over {} dof ({} iterations).\n\n"
                         "| key | start | fitted | error | unscaled error |\n|---|---|---|---|---|\n",
                         fr.chi2_start / fr.dof, fr.per_dof(), fr.dof, fr.iterations);
    std::string items;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      fmt::print("  {:<14} {:12.6g} -> {:12.6g} +- {:.3g} (unscaled {:.3g})\n", keys[i], fr.start[i],
                 fr.value[i], fr.error[i], fr.error_unscaled[i]);
      fit_md += fmt::format("| {} | {:.6g} | {:.6g} | {:.3g} | {:.3g} |\n", keys[i], fr.start[i], fr.value[i],
                            fr.error[i], fr.error_unscaled[i]);
      items += fmt::format("{}{{\"key\": {}, \"start\": {}, \"value\": {}, \"error\": {}, \"error_unscaled\": {}}}",
                           i ? ", " : "", compare::json_string(keys[i]), compare::json_number(fr.start[i]),
                           compare::json_number(fr.value[i]), compare::json_number(fr.error[i]),
                           compare::json_number(fr.error_unscaled[i]));
    }
    fit_json = fmt::format(
        "{{\"parameters\": [{}], \"chi2_start\": {}, \"chi2\": {}, \"dof\": {}, \"iterations\": {}, "
        "\"converged\": {}, \"error_scale\": \"sqrt(max(1, chi2/dof))\"}}",
        items, compare::json_number(fr.chi2_start), compare::json_number(fr.chi2), fr.dof, fr.iterations,
        fr.converged ? "true" : "false");
    // The verdict and the report use the fitted model.
    params = fr.params;
    model = compare::make_model(spec.name, params);
    bins = compare::predict_result(*model, result);
    j = judge(compare::compare(result, bins, params.alpha, copt), o);
    fmt::print("\nafter the fit: {}\n", describe(params));
    print_table(j, result.lobes);
  }

  int rejected = 0;
  for (std::size_t i = 0; i < j.rows.size(); ++i) rejected += j.rows[i].judged && !j.accepted[i];
  const std::string limit = o.max_chi2 > 0 ? fmt::format("chi2/dof <= {:g}", o.max_chi2)
                                           : std::string("chi2/dof <= 1 + 5 sqrt(2/dof)");
  fmt::print("\n{} of {} judged lobes accepted ({}); {:.1f} s\n", j.judged - rejected, j.judged, limit,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());

  if (!o.report.empty()) {
    compare::write_text(o.report, "metrics.csv", metrics_csv(j, result.lobes, o));
    const std::string json = fmt::format(
        "{{\n  \"kind\": \"compare\",\n  \"result\": {},\n  \"model\": {},\n  \"params\": {},\n  \"criterion\": {},\n"
        "  \"accepted\": {},\n  \"fit\": {},\n  \"lobes\": {}\n}}\n",
        compare::json_string(o.result), compare::json_string(spec.label), params_json(params),
        compare::json_string(limit), j.all ? "true" : "false", fit_json, rows_json(j, result.lobes, o));
    compare::write_text(o.report, "metrics.json", json);
    compare::write_compare_data(o.report, result, bins, spec.label, o.channel);
    const compare::PlotOutcome plots = compare::make_plots("compare", o.report);
    std::string md = fmt::format("# {} against {}\n\nModel parameters: `{}`\n\nCriterion per lobe: {}. "
                                 "Verdict: **{}** ({} of {} judged lobes accepted).\n\n",
                                 o.result, spec.label, describe(params), limit,
                                 j.all ? "accepted" : "rejected", j.judged - rejected, j.judged);
    md += "| theta_i | lobe | channel | E_sim +- se | E_model | chi2/dof (dof) | theta marg. | phi marg. | L1 | "
          "centroid sim / model (deg) | shift (deg) | verdict |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (std::size_t i = 0; i < j.rows.size(); ++i) {
      const auto& r = j.rows[i];
      md += fmt::format("| {:.2f} | {} | {} | {:.5f} +- {:.5f} | {:.5f} | {:.3f} ({}) | {:.3f} | {:.3f} | {:.3f} | "
                        "{:.2f} / {:.2f} | {:.2f} | {} |\n",
                        rad_to_deg(r.theta_i), compare::lobe_name(r.lobe, result.lobes), r.channel,
                        r.sim_energy, r.sim_error, r.model_energy, r.bins.per_dof(), r.bins.dof,
                        r.theta_marginal.per_dof(), r.phi_marginal.per_dof(), r.l1,
                        rad_to_deg(r.centroid_sim), rad_to_deg(r.centroid_model), rad_to_deg(r.measured_shift),
                        !r.judged ? "not judged" : (j.accepted[i] ? "ok" : "rejected"));
    }
    md += "\n" + fit_md;
    md += "\n## Plots\n\n";
    if (!plots.ran) md += plots.message + "\n\n";
    for (const std::string& png : plots.pngs) md += fmt::format("![{}]({})\n\n", png, png);
    md += "Numbers: `metrics.csv`, `metrics.json`; arrays: `report_data.h5`.\n";
    compare::write_text(o.report, "report.md", md);
    fmt::print("report: {}/report.md{}\n", o.report, plots.ran ? "" : " (" + plots.message + ")");
  }
  exit_code = j.all ? 0 : 1;
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Validate a model against a result's histograms (exit 0 accepted, 1 rejected, 2 bad input)");
  cmd->add_option("result", o->result, "Result file (.h5)")->required();
  cmd->add_option("--model", o->model,
                  "exact | deon2011 | marschner2003, optionally NAME:KEY=VALUE:... (per-model --set)")
      ->required();
  cmd->add_option("--set", o->settings, "Model parameter KEY=VALUE (angles in degrees); repeatable");
  cmd->add_option("--fit", o->fit,
                  "Comma-separated parameters to fit: eta, sigma_a, beta_long, beta_azim, alpha, scale_tilt, "
                  "or NAME[p] for one lobe's entry");
  cmd->add_option("--report", o->report, "Write a report folder (report.md, metrics.csv/json, PNG plots)");
  cmd->add_option("--max-chi2", o->max_chi2,
                  "Accept a lobe when chi2/dof <= X (default: 1 + 5 sqrt(2/dof), five standard deviations)");
  cmd->add_option("--min-effective", o->min_effective, "Bins compared one by one need S1^2/S2 >= this (30)");
  cmd->add_option("--model-error", o->model_error,
                  "Relative error assumed for the model's bin integrals (1e-4)");
  cmd->add_option("--min-energy", o->min_energy, "Lobes below this energy (both sides) are not judged (1e-4)");
  cmd->add_option("--channel", o->channel, "Channel shown in the plots (0)");
  cmd->callback([o] { compare_command(*o); });
}

}  // namespace fiberlab::cli
