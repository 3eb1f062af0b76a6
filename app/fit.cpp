#include "app/fit.h"

#include <set>

#include "analytic/model_registry.h"
#include "common/error.h"
#include "compare/fit_settings.h"
#include "compare/models.h"

namespace fiberlab::app {

compare::Verdict judge_model(const sim::ResultFile& result, const std::string& name,
                             const analytic::ModelParameters& params, const compare::Options& options,
                             double max_chi2) {
  const auto model = compare::make_model(name, params);
  return compare::judge(compare::compare(result, compare::predict_result(*model, result),
                                        analytic::theta_r_shifts(name, params), options),
                        max_chi2);
}

namespace {

// The verdict on one lobe's rows of `v` (judged again: the same rule row by
// row, and the counts, thresholds and all_accepted of those rows alone).
compare::Verdict only_lobe(const compare::Verdict& v, int lobe, double max_chi2) {
  std::vector<compare::LobeComparison> rows;
  for (const compare::LobeComparison& row : v.rows)
    if (row.lobe == lobe) rows.push_back(row);
  return compare::judge(std::move(rows), max_chi2);
}

}  // namespace

std::vector<LobeFitVerdict> fit_each_lobe(const sim::ResultFile& result, const std::string& model,
                                          const analytic::ModelParameters& start,
                                          const std::vector<std::string>& keys, const compare::Options& options,
                                          double max_chi2, int max_iterations, const compare::Verdict& before,
                                          const std::function<void(const std::string&)>& progress,
                                          const std::vector<std::string>& fit_settings) {
  std::vector<LobeFitVerdict> out;
  for (compare::LobeFit& lf : compare::fit_each_lobe(result, model, compare::with_fit_settings(model, start, fit_settings),
                                                     keys, options, max_iterations, progress)) {
    if (!fit_settings.empty()) compare::put_onto_judged(model, start, lf.fit);
    const compare::Verdict after = judge_model(result, model, lf.fit.params, options, max_chi2);
    out.push_back({lf.lobe, lf.fit, only_lobe(before, lf.lobe, max_chi2), only_lobe(after, lf.lobe, max_chi2)});
  }
  return out;
}

FitReport fit(const sim::ResultFile& result, const FitRequest& r,
              const std::function<void(const std::string&)>& progress) {
  compare::Options o = r.options;
  if (!r.lobes.empty()) o.lobes = compare::parse_fit_lobes(r.lobes, result.lobe_names(), "lobes");
  if (r.max_iterations < 1) throw Error("max_iterations must be an integer >= 1");
  if (r.keys.empty()) throw Error("fit: give at least one key to fit (e.g. [\"beta_long\"])");
  std::set<std::string> seen;
  for (const std::string& key : r.keys)
    if (!seen.insert(key).second) throw Error("fit key '" + key + "' is given twice");
  const compare::ModelSpec spec{r.model, {}, r.model};
  FitReport out;
  out.start = compare::params_for(result.settings, spec, r.sets);
  compare::make_model(spec.name, out.start);  // the model's own checks, before the fit
  for (const std::string& key : r.keys) compare::check_fit_key(spec.name, key);
  compare::check_fit_settings(spec.name, r.fit_settings, r.keys, "fit_settings");
  const analytic::ModelParameters fitting = compare::with_fit_settings(spec.name, out.start, r.fit_settings);
  const double limit = r.max_chi2 ? *r.max_chi2 : 0.0;
  out.before = judge_model(result, spec.name, out.start, o, limit);
  out.fit = compare::fit_model(result, spec.name, fitting, r.keys, o, r.max_iterations, progress);
  if (!r.fit_settings.empty()) compare::put_onto_judged(spec.name, out.start, out.fit);
  out.after = judge_model(result, spec.name, out.fit.params, o, limit);
  if (r.per_lobe)
    out.lobe_fits = fit_each_lobe(result, spec.name, out.start, r.keys, o, limit, r.max_iterations, out.before,
                                  progress, r.fit_settings);
  return out;
}

}  // namespace fiberlab::app
