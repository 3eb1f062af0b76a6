#pragma once
// Helpers for the comparison tests: simulations built in code, run in
// process, and the model bins of a result.
#include <cmath>
#include <string>
#include <vector>

#include "common/units.h"
#include "compare/comparison.h"
#include "compare/models.h"
#include "sim/store/result_file.h"
#include "sim/run/settings.h"
#include "sim/run/simulation.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::compare::testing {

// A white circular fiber without tilt (the simulator tests' smooth circle,
// seed 4242); `model` picks roughness.
inline sim::Settings circle(double theta_i_deg, std::uint64_t photons, const Roughness& model) {
  sim::Settings s = sim::testing::smooth_circle(theta_i_deg, photons);
  s.seed = 4242;
  s.fiber.roughness = model;
  return s;
}

using sim::testing::run;

// Model params for a result (analytic/physical_defaults.h, via compare::params_for) plus --set overrides.
inline analytic::ModelParameters params(const sim::ResultFile& r, const std::string& model,
                                    const std::vector<std::string>& settings = {}) {
  return params_for(r.settings, parse_model_spec(model), settings);
}

inline std::vector<LobeComparison> compare_with(const sim::ResultFile& r, const std::string& model,
                                                const std::vector<std::string>& settings = {}) {
  const analytic::ModelParameters p = params(r, model, settings);
  const auto m = compare::make_model(parse_model_spec(model).name, p);
  return compare(r, predict_result(*m, r), compare::theta_r_shifts(parse_model_spec(model).name, p));
}

// The acceptance rule of `fiberlab compare` without --max-chi2: chi2/dof
// within five standard deviations of its mean 1 (sd sqrt(2/dof), SPEC s10).
// With fixed seeds the outcome is deterministic; a correct model fails it
// with probability below 1e-5 per lobe for the dof used here.
inline double max_chi2_per_dof(int dof) { return 1.0 + 5.0 * std::sqrt(2.0 / dof); }

}  // namespace fiberlab::compare::testing
