#pragma once
// `fiberlab compare`: is model M (or any prediction file) right for the
// fiber of a result, where, and by how much? The statistics:
// compare/comparison.h; the rule: compare/verdict.h; the prediction format:
// compare/prediction_file.h; the fit: app/fit.h.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_parameters.h"
#include "app/fit.h"
#include "compare/comparison.h"
#include "compare/fit.h"
#include "compare/models.h"
#include "compare/verdict.h"
#include "sim/store/result_file.h"

namespace fiberlab::app {

// The flags of `fiberlab compare`, as given.
struct CompareRequest {
  std::string result, model, prediction, fit, report, fit_lobes;
  bool per_lobe = false;
  std::vector<std::string> settings;
  std::vector<std::string> fit_settings;  // --fit-set KEY=VALUE (compare/fit_settings.h)
  std::optional<double> max_chi2;  // none: the five-sigma rule of compare/verdict.h
  double min_effective = compare::Options{}.min_effective;
  double model_error = compare::Options{}.model_rel_error;
  double min_energy = compare::Options{}.min_lobe_energy;
  int channel = 0;
};

// The model's bins (or the prediction file's), their label and the lines
// that describe them.
struct Predicted {
  std::string label, header;
  std::vector<std::vector<double>> bins;
  std::vector<double> alpha;  // the model's theta_r shifts (empty for a file)
};

// A checked request: everything `compare` needs, read before any output.
struct Comparison {
  sim::ResultFile result;
  compare::Options options;      // the judging options
  compare::Options fit_options;  // with --fit-lobes
  double max_chi2 = 0.0;         // 0: the five-sigma rule
  bool from_file = false;
  compare::ModelSpec spec;         // --model
  analytic::ModelParameters params;    // --model, before any fit
  std::vector<std::string> fiber_notes;  // the approximate mappings from the simulated fiber
  std::vector<std::string> fit_keys;
  std::vector<std::string> fit_settings;  // applied only while fitting (compare/fit_settings.h)
  Predicted file_prediction;  // --prediction: the file's bins
};

// Checks the flags, reads the result and the model or prediction file, and
// checks that the report folder can be made. Throws fiberlab::Error.
Comparison set_up(const CompareRequest& request);

// The model's bins for the result.
Predicted predicted_by_model(const sim::ResultFile& result, const compare::ModelSpec& spec,
                             const analytic::ModelParameters& params,
                             const std::vector<std::string>& fiber_notes = {});

// The verdict on `predicted`.
compare::Verdict judge(const Comparison& c, const Predicted& predicted);

// --fit: the joint fit from c.params and the verdict after it.
struct JointFit {
  compare::FitResult fit;
  Predicted predicted;  // at the fitted parameters
  compare::Verdict after;
};
JointFit fit_jointly(const Comparison& c, const std::function<void(const std::string&)>& progress);

// --per-lobe: each lobe fitted alone from c.params (app/fit.h
// fit_each_lobe, which fiberlab.fit(per_lobe=True) calls too), with that
// lobe's rows of the verdicts before and after.
std::vector<LobeFitVerdict> fit_each_lobe(const Comparison& c, const compare::Verdict& before,
                                          const std::function<void(const std::string&)>& progress);

}  // namespace fiberlab::app
