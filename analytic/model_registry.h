#pragma once
// Every analytic model by name: its parameter table, how to build it, which
// published approximations are in effect, and how a physical fiber's
// description becomes its parameters.
//
// Adding a model: its parameter struct and model class in one header and
// source file (deon2011.h / deon2011.cpp), and at the end of the source a
// `ModelInfo NAME_info()` built by define_model() from a ModelDefinition of
// that struct (a name, a citation, a ParamTable bound to the struct's
// fields, a factory, its approximations, its rule from a simulated fiber and
// its theta_r shifts); then that one call in the list in
// model_registry.cpp. Everything else (--set, the checks, `fiberlab
// models`, predict/compare headers, the prediction's attributes, the fit)
// follows from it.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_params.h"
#include "analytic/physical_defaults.h"

namespace fiberlab::analytic {

// A registered model, its struct erased: every function takes the model's
// parameters as a ModelParameters holding that struct (owns() says whether
// it does; the registry's functions below check it).
struct ModelInfo {
  std::string name;       // --model NAME
  std::string reference;  // the paper, or what the model is
  ParamTable params;
  // The model's struct as constructed (before the table's defaults).
  std::function<ModelParameters()> blank;
  std::function<bool(const ModelParameters&)> owns;
  std::function<std::unique_ptr<Model>(const ModelParameters&)> make;
  // The published approximations (and departures from the exact smooth
  // cylinder, SPEC s7) in effect with these parameters, one line each,
  // printed in predict/compare headers so that a difference is never
  // mistaken for a simulator error.
  std::function<std::vector<std::string>(const ModelParameters&)> approximations;
  // The model's parameters for a simulated fiber: the table's defaults with
  // the fiber's eta, sigma_a, lobes, eccentricity (where the model has it),
  // roughness and tilt mapped by the model's rule (physical_defaults.h). A
  // fiber the model cannot represent: fiberlab::Error naming the field and
  // what is allowed, unless mapping.user_sets() the key concerned; an
  // approximate rule adds a line to mapping.notes.
  std::function<void(const PhysicalFiber&, ModelParameters&, FiberMapping&)> from_fiber;
  // The shift of each lobe's theta_r (radians, per lobe p, the last entry
  // for every larger p) that the model applies (SPEC s7), for the shift
  // column of a comparison (compare/comparison.h).
  std::function<std::vector<double>(const ModelParameters&)> theta_r_shifts;
};

// A model's entry written against its own struct P; define_model() erases P.
template <class P>
struct ModelDefinition {
  std::string name;
  std::string reference;
  ParamTable params;
  std::function<std::unique_ptr<Model>(const P&)> make;
  std::function<std::vector<std::string>(const P&)> approximations;
  std::function<void(const PhysicalFiber&, P&, FiberMapping&)> from_fiber;
  std::function<std::vector<double>(const P&)> theta_r_shifts;
};

template <class P>
ModelInfo define_model(ModelDefinition<P> d) {
  ModelInfo m;
  m.name = std::move(d.name);
  m.reference = std::move(d.reference);
  m.params = std::move(d.params);
  m.blank = [] { return ModelParameters(P{}); };
  m.owns = [](const ModelParameters& p) { return p.holds<P>(); };
  m.make = [make = std::move(d.make)](const ModelParameters& p) { return make(p.as<P>()); };
  m.approximations = [f = std::move(d.approximations)](const ModelParameters& p) { return f(p.as<P>()); };
  m.from_fiber = [f = std::move(d.from_fiber)](const PhysicalFiber& fiber, ModelParameters& p,
                                               FiberMapping& mapping) { f(fiber, p.as<P>(), mapping); };
  m.theta_r_shifts = [f = std::move(d.theta_r_shifts)](const ModelParameters& p) { return f(p.as<P>()); };
  return m;
}

// Every registered model, in listing order.
const std::vector<ModelInfo>& registered_models();
std::vector<std::string> model_names();
// The model called `name`; fiberlab::Error naming the allowed names otherwise.
const ModelInfo& model_info(const std::string& name);

// The table's defaults of model `name`.
ModelParameters default_params(const std::string& name);
// The defaults for a simulated fiber (ModelInfo::from_fiber).
ModelParameters params_for_fiber(const std::string& name, const PhysicalFiber& fiber);
// --set KEY=VALUE for model `name` (unknown key: exit-2 error listing its keys).
void apply_setting(const std::string& name, ModelParameters& params, const std::string& key_value);
void apply_settings(const std::string& name, ModelParameters& params,
                    const std::vector<std::string>& key_values);

// Builds the model (its own checks may throw fiberlab::Error).
std::unique_ptr<Model> make_model(const std::string& name, const ModelParameters& params);

// "key=value ..." of the model's parameters ("" for an empty
// ModelParameters, e.g. a model not fitted); attributes for a file.
std::string describe_params(const std::string& name, const ModelParameters& params);
std::vector<ParamAttribute> param_attributes(const std::string& name, const ModelParameters& params);
std::vector<std::string> approximations(const std::string& name, const ModelParameters& params);
// The model's theta_r shift per lobe (radians; ModelInfo::theta_r_shifts).
std::vector<double> theta_r_shifts(const std::string& name, const ModelParameters& params);
// The tally lobes and colour channels the model predicts with these
// parameters (its table's `lobes` and the length of its `sigma_a`).
int predicted_lobes(const std::string& name, const ModelParameters& params);
int predicted_channels(const std::string& name, const ModelParameters& params);

// The listing of `fiberlab models` (every model, its keys with meaning,
// unit, default, allowed values and config source): plain text, or a
// Markdown section for the README.
std::string models_listing(bool markdown = false);

}  // namespace fiberlab::analytic
