// `fiberlab compare RESULT.h5 --model M [--set KEY=VALUE ...] [--fit KEYS]
//                  [--report DIR] [--max-chi2 X]`
// `fiberlab compare RESULT.h5 --prediction PRED.h5 [--report DIR] [--max-chi2 X]`
// Is model M (or any prediction file) right for the fiber of RESULT, where,
// and by how much? Exit status 0 when every judged lobe is accepted, 1 when
// one is not, 2 on bad input. The statistics: compare/comparison.h; the rule:
// compare/verdict.h; the prediction format: compare/prediction_file.h.
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>

#include "analytic/model_registry.h"
#include "cli/commands.h"
#include "common/error.h"
#include "common/units.h"
#include "compare/compare_report.h"
#include "compare/comparison.h"
#include "compare/fit.h"
#include "compare/fit_text.h"
#include "compare/models.h"
#include "compare/prediction_file.h"
#include "compare/verdict.h"
#include "compare/report.h"
#include "compare/verdict_tables.h"
#include "sim/store/result_file.h"

namespace fiberlab::cli {

namespace {

struct CompareOptions {
  std::string result, model, prediction, fit, report, fit_lobes;
  bool per_lobe = false;
  std::vector<std::string> settings;
  std::optional<double> max_chi2;  // none: the five-sigma rule of compare/verdict.h
  double max_chi2_value = 0.0;
  double min_effective = 30.0, model_error = 1e-4, min_energy = 1e-4;
  int channel = 0;
};

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, ','))
    if (!part.empty()) out.push_back(part);
  return out;
}

// The model's bins (or the prediction file's), their label and the lines
// that describe them.
struct Predicted {
  std::string label, header;
  std::vector<std::vector<double>> bins;
  std::vector<double> alpha;  // the model's theta_r shifts (empty for a file)
};

Predicted predicted_by_model(const sim::ResultFile& result, const compare::ModelSpec& spec,
                             const analytic::ModelParams& params,
                             const std::vector<std::string>& fiber_notes = {}) {
  Predicted p;
  p.label = spec.label;
  p.header = compare::model_header(spec, params, fiber_notes);
  p.bins = compare::predict_result(*compare::make_model(spec.name, params), result);
  p.alpha = params.alpha;
  return p;
}

Predicted predicted_by_file(const sim::ResultFile& result, const CompareOptions& o) {
  const compare::PredictionFile file = compare::read_prediction_for(o.prediction, result, o.result);
  Predicted p;
  p.label = fmt::format("{} (model {})", o.prediction, file.model.empty() ? "not named" : file.model);
  p.header = "prediction " + p.label + "\n";
  if (!file.approximations.empty()) {
    p.header += "  approximations in effect (from the file):\n";
    for (const auto& a : file.approximations) p.header += "  - " + a + "\n";
  }
  p.bins = compare::prediction_bins_for(file, result, o.result);
  return p;
}

// --per-lobe: compare::fit_each_lobe's fits printed, each with its lobe's
// chi2/dof before and after; returned as markdown for the report. The
// verdict stays the joint fit's.
std::string per_lobe_fits(const sim::ResultFile& result, const compare::ModelSpec& spec,
                          const analytic::ModelParams& start, const std::vector<std::string>& keys,
                          const compare::Options& joint, double max_chi2, const compare::Verdict& before) {
  std::string md = "\n## Per-lobe fits\n";
  for (const compare::LobeFit& lf : compare::fit_each_lobe(
           result, spec.name, start, keys, joint, 40, [](const std::string& line) { fmt::print(stderr, "{}\n", line); })) {
    const Predicted fitted = predicted_by_model(result, spec, lf.fit.params);
    const compare::Verdict after =
        compare::judge(compare::compare(result, fitted.bins, fitted.alpha, joint), max_chi2);
    auto only = [&](const compare::Verdict& v) {  // this lobe's rows
      compare::Verdict w = v;
      w.rows.clear();
      w.accepted.clear();
      for (std::size_t i = 0; i < v.rows.size(); ++i)
        if (v.rows[i].lobe == lf.lobe) {
          w.rows.push_back(v.rows[i]);
          w.accepted.push_back(v.accepted[i]);
        }
      return w;
    };
    const std::string name = compare::lobe_name(lf.lobe, result.lobes);
    fmt::print("\nper-lobe fit of {}:", name);
    fmt::print("{}", compare::fit_text(lf.fit, only(before), only(after), result.lobes));
    md += fmt::format("\n### {}\n\n", name) + compare::fit_markdown(lf.fit, only(before), only(after), result.lobes);
  }
  return md;
}

void compare_command(const CompareOptions& o) {
  compare::Options copt;
  copt.min_effective = o.min_effective;
  copt.model_rel_error = o.model_error;
  copt.min_lobe_energy = o.min_energy;
  compare::check_options(copt, o.max_chi2, compare::OptionSpelling::CommandLine);
  const double max_chi2 = o.max_chi2.value_or(0.0);  // 0: the five-sigma rule
  const bool from_file = !o.prediction.empty();
  if (from_file == !o.model.empty())
    throw Error("compare: give either --model NAME or --prediction PRED.h5 (exactly one)");
  if (from_file && (!o.settings.empty() || !o.fit.empty()))
    throw Error("compare --prediction: --set and --fit need a --model (a file's parameters cannot be changed)");
  if (o.fit.empty() && (o.per_lobe || !o.fit_lobes.empty()))
    throw Error("compare: --fit-lobes and --per-lobe need --fit KEYS");
  const sim::ResultFile result = sim::read_result(o.result);
  if (o.channel < 0 || o.channel >= result.channels)
    throw Error(fmt::format("--channel {} out of range (the result has {} channels)", o.channel, result.channels));
  compare::ModelSpec spec;
  analytic::ModelParams params;
  std::vector<std::string> fiber_notes;
  if (!from_file) {
    spec = compare::parse_model_spec(o.model);
    params = compare::params_for(result.settings, spec, o.settings, &fiber_notes);
    analytic::make_model(spec.name, params);  // the model's own checks, before any output
    compare::check_fit_keys(spec.name, split_commas(o.fit));
  }
  compare::Options fit_opt = copt;  // the lobes the fit judges and fits
  if (!o.fit_lobes.empty())
    fit_opt.lobes = compare::parse_fit_lobes(split_commas(o.fit_lobes), result.lobes, "--fit-lobes");
  const Predicted pred = from_file ? predicted_by_file(result, o) : Predicted{};
  if (!o.report.empty()) compare::make_report_dir(o.report);

  const auto t0 = std::chrono::steady_clock::now();
  fmt::print("{}: {} incident direction(s), {} lobes, {} channel(s), {} x {} bins\n", o.result,
             result.configs(), result.lobes, result.channels, result.grid.n_theta(), result.grid.n_phi());
  Predicted current = from_file ? pred : predicted_by_model(result, spec, params, fiber_notes);
  fmt::print("{}", current.header);
  compare::Verdict v = compare::judge(compare::compare(result, current.bins, current.alpha, copt), max_chi2);
  fmt::print("{}", compare::verdict_table(v, result.lobes));

  std::string fit_json = "null", fit_md;
  if (!o.fit.empty()) {
    const compare::FitResult fr = compare::fit_model(
        result, spec.name, params, split_commas(o.fit), fit_opt, 40,
        [](const std::string& line) { fmt::print(stderr, "{}\n", line); });
    const analytic::ModelParams start = params;
    // The verdict and the report use the fitted model.
    params = fr.params;
    current = predicted_by_model(result, spec, params);
    const compare::Verdict before = v;
    v = compare::judge(compare::compare(result, current.bins, current.alpha, copt), max_chi2);
    fmt::print("{}", compare::fit_text(fr, before, v, result.lobes));
    fit_md = compare::fit_markdown(fr, before, v, result.lobes);
    fit_json = compare::fit_json(fr, before, v);
    fmt::print("\nafter the fit: {}", current.header);
    fmt::print("{}", compare::verdict_table(v, result.lobes));
    if (o.per_lobe) fit_md += per_lobe_fits(result, spec, start, split_commas(o.fit), fit_opt, max_chi2, before);
  }

  fmt::print("\n{} of {} judged lobes accepted ({}); {:.1f} s\n", v.judged - v.rejected, v.judged, v.criterion,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (v.judged == 0)
    fmt::print("no lobe was judged (each has energy below --min-energy = {:g} in both the result and "
               "the prediction, or no compared bins): nothing is accepted, exit status 1\n",
               o.min_energy);

  if (!o.report.empty()) {
    compare::CompareReport rep;
    rep.dir = o.report;
    rep.result_path = o.result;
    rep.label = current.label;
    rep.header = current.header;
    if (!from_file) rep.params_json = compare::params_json(spec.name, params);
    rep.fit_json = fit_json;
    rep.fit_markdown = fit_md;
    rep.plot_channel = o.channel;
    fmt::print("{}", compare::write_compare_report(rep, result, current.bins, v));
  }
  exit_code = v.all_accepted ? 0 : 1;
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Validate a model against a result's histograms (exit 0: every judged lobe accepted, "
                 "at least one judged; 1: a lobe rejected, or none judged; 2: bad input)");
  cmd->add_option("result", o->result, "Result file (.h5)")->required();
  cmd->add_option("--model", o->model,
                  fmt::format("{}, optionally NAME:KEY=VALUE:... (per-model --set)",
                              fmt::join(analytic::model_names(), " | ")));
  cmd->add_option("--prediction", o->prediction,
                  "Judge a prediction file instead of a built-in model (format fiber-prediction: "
                  "docs/FILE_FORMAT.md)");
  cmd->add_option("--set", o->settings,
                  "Model parameter KEY=VALUE (angles in degrees; repeatable; `fiberlab models` lists the keys)");
  cmd->add_option("--fit", o->fit,
                  "Comma-separated parameters to fit: the model's numeric keys (eta, beta_long, beta_m, ...), NAME[p] "
                  "for one lobe's entry (beta_long[0],alpha[2]), or the physical scale_tilt (shift rule)");
  cmd->add_option("--fit-lobes", o->fit_lobes,
                  "Comma-separated lobes the fit judges and fits (R,TT,TRT,p>=3 or indices; default every lobe)");
  cmd->add_flag("--per-lobe", o->per_lobe,
                "Also fit each lobe alone (its own beta_long[p], beta_azim[p], alpha[p] where the model has them), "
                "after the joint fit");
  cmd->add_option("--report", o->report, "Write a report folder (report.md, metrics.csv/json, PNG plots)");
  CLI::Option* max_chi2 = cmd->add_option("--max-chi2", o->max_chi2_value,
                  "Accept a lobe when chi2/dof <= X, X > 0 (default: 1 + 5 sqrt(2/dof), five standard deviations)");
  cmd->add_option("--min-effective", o->min_effective, "Bins compared one by one need S1^2/S2 >= this (30)");
  cmd->add_option("--model-error", o->model_error,
                  "Relative error assumed for the model's bin integrals, in [0, 1] (1e-4)");
  cmd->add_option("--min-energy", o->min_energy,
                  "Lobes below this energy (both sides) are not judged, in [0, 1) (1e-4); when no lobe "
                  "is judged nothing is accepted (exit 1)");
  cmd->add_option("--channel", o->channel, "Channel shown in the plots (0)");
  // Built when --help asks for it, not at every start (about 0.3 ms each).
  cmd->footer([] { return "\nModel parameters (--set KEY=VALUE):\n\n" + analytic::models_listing(); });
  cmd->callback([o, max_chi2] {
    if (max_chi2->count() > 0) o->max_chi2 = o->max_chi2_value;
    compare_command(*o);
  });
}

}  // namespace fiberlab::cli
