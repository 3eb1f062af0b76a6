#pragma once
// fiberlab.fit: the fit of `fiberlab compare --fit` (compare/fit.h) on a
// result, started from the model's parameters for the result's fiber, with
// the verdicts before and after it; and the verdict on one set of a model's
// parameters, which `fiberlab compare` and fiberlab.fit both give.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_parameters.h"
#include "compare/comparison.h"
#include "compare/fit.h"
#include "compare/verdict.h"
#include "sim/store/result_file.h"

namespace fiberlab::app {

// Levenberg-Marquardt iterations a fit may take (`compare --fit`, fiberlab.fit's default).
inline constexpr int kFitIterations = 40;

// The verdict (compare::judge, max_chi2 0: the five-sigma rule) on model
// `name` with `params` against `result`.
compare::Verdict judge_model(const sim::ResultFile& result, const std::string& name,
                             const analytic::ModelParameters& params, const compare::Options& options,
                             double max_chi2);

struct FitRequest {
  std::string model;
  std::vector<std::string> keys;   // what to fit (compare::check_fit_key)
  std::vector<std::string> sets;   // KEY=VALUE overrides of the start
  std::vector<std::string> lobes;  // the lobes the fit judges and fits; empty: every lobe
  compare::Options options;        // checked by compare::check_options
  std::optional<double> max_chi2;
  int max_iterations = kFitIterations;
};

struct FitReport {
  analytic::ModelParameters start;
  compare::FitResult fit;
  compare::Verdict before, after;
};

// Checks the request (keys given once each, the model's own checks), then
// fits. `progress` gets compare::fit_model's line per iteration; what it
// throws ends the fit and leaves here.
FitReport fit(const sim::ResultFile& result, const FitRequest& request,
              const std::function<void(const std::string&)>& progress = {});

}  // namespace fiberlab::app
