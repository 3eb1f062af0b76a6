#include "app/fit.h"

#include <set>

#include "analytic/model_registry.h"
#include "common/error.h"
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

FitReport fit(const sim::ResultFile& result, const FitRequest& r,
              const std::function<void(const std::string&)>& progress) {
  compare::Options o = r.options;
  if (!r.lobes.empty()) o.lobes = compare::parse_fit_lobes(r.lobes, result.lobes, "lobes");
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
  const double limit = r.max_chi2 ? *r.max_chi2 : 0.0;
  out.before = judge_model(result, spec.name, out.start, o, limit);
  out.fit = compare::fit_model(result, spec.name, out.start, r.keys, o, r.max_iterations, progress);
  out.after = judge_model(result, spec.name, out.fit.params, o, limit);
  return out;
}

}  // namespace fiberlab::app
