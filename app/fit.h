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
  std::vector<std::string> fit_settings;  // KEY=VALUE applied only while fitting (compare/fit_settings.h)
  std::vector<std::string> lobes;  // the lobes the fit judges and fits; empty: every lobe
  compare::Options options;        // checked by compare::check_options
  std::optional<double> max_chi2;
  int max_iterations = kFitIterations;
  bool per_lobe = false;  // also fit each lobe alone (fit_each_lobe), as `compare --per-lobe`
};

// One lobe fitted alone, with that lobe's rows of the verdicts before and
// after its fit.
struct LobeFitVerdict {
  int lobe = 0;
  compare::FitResult fit;
  compare::Verdict before, after;  // this lobe's rows only
};

struct FitReport {
  analytic::ModelParameters start;
  compare::FitResult fit;
  compare::Verdict before, after;
  std::vector<LobeFitVerdict> lobe_fits;  // with per_lobe
};

// Each lobe of options.lobes (every lobe when empty) fitted alone from
// `start` (compare::fit_each_lobe: a per-lobe key becomes the lobe's own
// entry), judged after its fit with `options` and `max_chi2` (0: the
// five-sigma rule); `before` is the verdict at `start`, of which each lobe
// keeps its rows. `fit_settings` apply while fitting only: each lobe's
// params are then `start` at its fitted values (compare/fit_settings.h). `compare --per-lobe` and fiberlab.fit(per_lobe=True) both
// give these.
std::vector<LobeFitVerdict> fit_each_lobe(const sim::ResultFile& result, const std::string& model,
                                          const analytic::ModelParameters& start,
                                          const std::vector<std::string>& keys, const compare::Options& options,
                                          double max_chi2, int max_iterations, const compare::Verdict& before,
                                          const std::function<void(const std::string&)>& progress = {},
                                          const std::vector<std::string>& fit_settings = {});

// Checks the request (keys given once each, the model's own checks), then
// fits (jointly; with per_lobe, then each lobe alone from the same start). `progress` gets compare::fit_model's line per iteration; what it
// throws ends the fit and leaves here.
FitReport fit(const sim::ResultFile& result, const FitRequest& request,
              const std::function<void(const std::string&)>& progress = {});

}  // namespace fiberlab::app
