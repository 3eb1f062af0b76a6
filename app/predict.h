#pragma once
// `fiberlab predict` and fiberlab.predict: an analytic model's bin
// probabilities for the histogram a simulation with these settings produces
// (SPEC section 7), in the same layout.
#include <memory>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_parameters.h"
#include "compare/models.h"
#include "compare/prediction_file.h"
#include "sim/run/settings.h"

namespace fiberlab::app {

// A model chosen for a fiber: its parameters (compare::params_for: the
// config's defaults, then KEY=VALUE overrides) and the model built from them
// (which makes the model's own checks).
struct ChosenModel {
  compare::ModelSpec spec;
  analytic::ModelParameters params;
  std::vector<std::string> fiber_notes;  // the approximate mappings from the simulated fiber
  std::unique_ptr<analytic::Model> model;
};
ChosenModel choose_model(const sim::Settings& settings, const compare::ModelSpec& spec,
                         const std::vector<std::string>& sets);

// The model's bin probabilities for every incident direction of `settings`
// (compare::predict_bins), with the grid, lobes and channels of the file.
compare::PredictionFile predict(const sim::Settings& settings, const ChosenModel& chosen);

}  // namespace fiberlab::app
