#pragma once
// Every analytic model by name: its parameter table, how to build it, which
// published approximations are in effect, and how a physical fiber's
// description becomes its parameters.
//
// Adding a model: write its ModelInfo (a name, a citation, a ParamTable, a
// factory, its approximations and its physical defaults) beside the model,
// e.g. `ModelInfo deon2011_info()` at the end of deon2011.cpp, and add that
// one call to the list in model_registry.cpp. Everything else (--set, the
// checks, `fiberlab models`, predict/compare headers, the prediction's
// attributes) follows from it.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_params.h"
#include "analytic/physical_defaults.h"

namespace fiberlab::analytic {

struct ModelInfo {
  std::string name;       // --model NAME
  std::string reference;  // the paper, or what the model is
  ParamTable params;
  std::function<std::unique_ptr<Model>(const ModelParams&)> make;
  // The published approximations (and departures from the exact smooth
  // cylinder, SPEC s7) in effect with these parameters, one line each,
  // printed in predict/compare headers so that a difference is never
  // mistaken for a simulator error.
  std::function<std::vector<std::string>(const ModelParams&)> approximations;
  // The model's parameters for a simulated fiber: the table's defaults with
  // the fiber's eta, sigma_a, lobes, eccentricity (where the model has it),
  // roughness and tilt mapped by the model's rule (physical_defaults.h). A
  // fiber the model cannot represent: fiberlab::Error naming the field and
  // what is allowed, unless mapping.user_sets() the key concerned; an
  // approximate rule adds a line to mapping.notes.
  std::function<void(const PhysicalFiber&, ModelParams&, FiberMapping&)> from_fiber;
};

// Every registered model, in listing order.
const std::vector<ModelInfo>& registered_models();
std::vector<std::string> model_names();
// The model called `name`; fiberlab::Error naming the allowed names otherwise.
const ModelInfo& model_info(const std::string& name);

// The table's defaults of model `name`.
ModelParams default_params(const std::string& name);
// The defaults for a simulated fiber (ModelInfo::from_fiber).
ModelParams params_for_fiber(const std::string& name, const PhysicalFiber& fiber);
// --set KEY=VALUE for model `name` (unknown key: exit-2 error listing its keys).
void apply_setting(const std::string& name, ModelParams& params, const std::string& key_value);
void apply_settings(const std::string& name, ModelParams& params,
                    const std::vector<std::string>& key_values);

// Builds the model (its own checks may throw fiberlab::Error).
std::unique_ptr<Model> make_model(const std::string& name, const ModelParams& params);

// "key=value ..." of the model's parameters; attributes for a file.
std::string describe_params(const std::string& name, const ModelParams& params);
std::vector<ParamAttribute> param_attributes(const std::string& name, const ModelParams& params);
std::vector<std::string> approximations(const std::string& name, const ModelParams& params);

// The listing of `fiberlab models` (every model, its keys with meaning,
// unit, default, allowed values and config source): plain text, or a
// Markdown section for the README.
std::string models_listing(bool markdown = false);

}  // namespace fiberlab::analytic
