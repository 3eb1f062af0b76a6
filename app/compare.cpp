#include "app/compare.h"

#include <fmt/core.h>

#include <sstream>

#include "analytic/model_registry.h"
#include "app/fit.h"
#include "app/comma_list.h"
#include "common/error.h"
#include "compare/fit_settings.h"
#include "compare/prediction_file.h"
#include "compare/report.h"

namespace fiberlab::app {

namespace {

Predicted predicted_by_file(const sim::ResultFile& result, const CompareRequest& o) {
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

}  // namespace

Comparison set_up(const CompareRequest& o) {
  Comparison c;
  compare::Options& copt = c.options;
  copt.min_effective = o.min_effective;
  copt.model_rel_error = o.model_error;
  copt.min_lobe_energy = o.min_energy;
  compare::check_options(copt, o.max_chi2, compare::OptionSpelling::CommandLine);
  c.max_chi2 = o.max_chi2.value_or(0.0);  // 0: the five-sigma rule
  c.from_file = !o.prediction.empty();
  if (c.from_file == !o.model.empty())
    throw Error("compare: give either --model NAME or --prediction PRED.h5 (exactly one)");
  if (c.from_file && (!o.settings.empty() || !o.fit.empty()))
    throw Error("compare --prediction: --set and --fit need a --model (a file's parameters cannot be changed)");
  if (o.fit.empty() && (o.per_lobe || !o.fit_lobes.empty() || !o.fit_settings.empty()))
    throw Error("compare: --fit-lobes, --per-lobe and --fit-set need --fit KEYS");
  c.result = sim::read_result(o.result);
  const sim::ResultFile& result = c.result;
  if (o.channel < 0 || o.channel >= result.channels)
    throw Error(fmt::format("--channel {} out of range (the result has {} channels)", o.channel, result.channels));
  c.fit_keys = split_commas(o.fit);
  if (!c.from_file) {
    c.spec = compare::parse_model_spec(o.model);
    c.params = compare::params_for(result.settings, c.spec, o.settings, &c.fiber_notes);
    compare::make_model(c.spec.name, c.params);  // the model's own checks, before any output
    compare::check_fit_keys(c.spec.name, c.fit_keys);
    compare::check_fit_settings(c.spec.name, o.fit_settings, c.fit_keys, "--fit-set");
    c.fit_settings = o.fit_settings;
    compare::with_fit_settings(c.spec.name, c.params, c.fit_settings);  // the model's own checks
  }
  c.fit_options = copt;  // the lobes the fit judges and fits
  if (!o.fit_lobes.empty())
    c.fit_options.lobes = compare::parse_fit_lobes(split_commas(o.fit_lobes), result.lobe_names(), "--fit-lobes");
  if (c.from_file) c.file_prediction = predicted_by_file(result, o);
  if (!o.report.empty()) compare::make_report_dir(o.report);
  return c;
}

Predicted predicted_by_model(const sim::ResultFile& result, const compare::ModelSpec& spec,
                             const analytic::ModelParameters& params,
                             const std::vector<std::string>& fiber_notes) {
  Predicted p;
  p.label = spec.label;
  p.header = compare::model_header(spec, params, fiber_notes);
  p.bins = compare::predict_result(*compare::make_model(spec.name, params), result);
  p.alpha = analytic::theta_r_shifts(spec.name, params);
  return p;
}

compare::Verdict judge(const Comparison& c, const Predicted& p) {
  return compare::judge(compare::compare(c.result, p.bins, p.alpha, c.options), c.max_chi2);
}

JointFit fit_jointly(const Comparison& c, const std::function<void(const std::string&)>& progress) {
  JointFit j;
  j.fit = compare::fit_model(c.result, c.spec.name, compare::with_fit_settings(c.spec.name, c.params, c.fit_settings),
                             c.fit_keys, c.fit_options, kFitIterations, progress);
  if (!c.fit_settings.empty()) compare::put_onto_judged(c.spec.name, c.params, j.fit);
  // The verdict and the report use the fitted model.
  j.predicted = predicted_by_model(c.result, c.spec, j.fit.params);
  j.after = judge(c, j.predicted);
  return j;
}

std::vector<LobeFitVerdict> fit_each_lobe(const Comparison& c, const compare::Verdict& before,
                                          const std::function<void(const std::string&)>& progress) {
  // Each lobe is judged with the fit's options; the command's verdict stays the joint fit's.
  return app::fit_each_lobe(c.result, c.spec.name, c.params, c.fit_keys, c.fit_options, c.max_chi2, kFitIterations,
                            before, progress, c.fit_settings);
}

}  // namespace fiberlab::app
