#include "analytic/model_registry.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <map>

#include "common/error.h"

namespace fiberlab::analytic {

// Each model's entry, defined beside the model.
ModelInfo exact_info();          // smooth_cylinder.cpp
ModelInfo deon2011_info();       // deon2011.cpp
ModelInfo marschner2003_info();  // marschner2003.cpp
ModelInfo chiang2016_info();     // chiang2016.cpp
ModelInfo huang2022_info();      // huang2022.cpp

const std::vector<ModelInfo>& registered_models() {
  // To add a model: declare its info function above and list it here.
  static const std::vector<ModelInfo> models{exact_info(), deon2011_info(), marschner2003_info(),
                                             chiang2016_info(), huang2022_info()};
  return models;
}

std::vector<std::string> model_names() {
  std::vector<std::string> names;
  for (const ModelInfo& m : registered_models()) names.push_back(m.name);
  return names;
}

const ModelInfo& model_info(const std::string& name) {
  for (const ModelInfo& m : registered_models())
    if (m.name == name) return m;
  throw Error(fmt::format("--model {}: unknown model; allowed: {}", name, fmt::join(model_names(), " | ")));
}

namespace {
// The model called `name`, after checking that `params` hold its struct: a
// table applied to another model's struct would read the wrong fields.
const ModelInfo& owner(const std::string& name, const ModelParameters& params) {
  const ModelInfo& m = model_info(name);
  if (!m.owns(params))
    throw Error(fmt::format("model {}: the parameters given are not {}'s ({})", name, name,
                            params.empty() ? "none" : "another model's"));
  return m;
}
}  // namespace

ModelParameters default_params(const std::string& name) {
  const ModelInfo& m = model_info(name);
  return table_defaults(m.params, m.blank());
}

ModelParameters params_for_fiber(const std::string& name, const PhysicalFiber& fiber) {
  const ModelInfo& m = model_info(name);
  ModelParameters p = table_defaults(m.params, m.blank());
  FiberMapping mapping;
  m.from_fiber(fiber, p, mapping);
  return p;
}

void apply_setting(const std::string& name, ModelParameters& params, const std::string& key_value) {
  const ModelInfo& m = owner(name, params);
  apply_setting(m.name, m.params, params, key_value);
}

void apply_settings(const std::string& name, ModelParameters& params,
                    const std::vector<std::string>& key_values) {
  // Each key once: a repeated key would keep its last value silently.
  std::map<std::string, std::string> seen;
  for (const std::string& kv : key_values) {
    const std::size_t eq = kv.find('=');
    if (eq != std::string::npos) {
      std::string key = kv.substr(0, eq);
      key.erase(0, key.find_first_not_of(" \t"));
      key.erase(key.find_last_not_of(" \t") + 1);
      const auto [it, fresh] = seen.emplace(key, kv);
      if (!fresh)
        throw Error(fmt::format("--set {}: {} is already set by --set {} (give each key once)", kv,
                                key, it->second));
    }
    apply_setting(name, params, kv);
  }
}

std::unique_ptr<Model> make_model(const std::string& name, const ModelParameters& params) {
  const ModelInfo& m = owner(name, params);
  check_params(m.name, m.params, params);
  return m.make(params);
}

std::string describe_params(const std::string& name, const ModelParameters& params) {
  if (params.empty()) return "";  // no parameters (a model not fitted): nothing to describe
  return describe(owner(name, params).params, params);
}

std::vector<ParamAttribute> param_attributes(const std::string& name, const ModelParameters& params) {
  return to_attributes(owner(name, params).params, params);
}

std::vector<std::string> approximations(const std::string& name, const ModelParameters& params) {
  return owner(name, params).approximations(params);
}

std::vector<double> theta_r_shifts(const std::string& name, const ModelParameters& params) {
  return owner(name, params).theta_r_shifts(params);
}

namespace {
// The value of `key` in its table entry's file form (every model has lobes and sigma_a).
std::vector<double> table_numbers(const std::string& name, const ModelParameters& params, const std::string& key) {
  const ModelInfo& m = owner(name, params);
  const ParamSpec* spec = find_param(m.params, key);
  if (!spec) throw Error(fmt::format("model {} has no parameter '{}'", name, key));
  return spec->attribute(params).numbers;
}
}  // namespace

int predicted_lobes(const std::string& name, const ModelParameters& params) {
  return static_cast<int>(table_numbers(name, params, "lobes").at(0));
}

int predicted_channels(const std::string& name, const ModelParameters& params) {
  return static_cast<int>(table_numbers(name, params, "sigma_a").size());
}

std::string models_listing(bool markdown) {
  std::string s;
  for (const ModelInfo& m : registered_models()) {
    if (markdown) {
      s += fmt::format("### `{}`: {}\n\n| key | meaning | unit | default | allowed | from a simulation |\n"
                       "|---|---|---|---|---|---|\n",
                       m.name, m.reference);
      // A "|" inside a cell (choices "a | b") would end the cell.
      auto cell = [](std::string text) {
        for (std::size_t i = text.find('|'); i != std::string::npos; i = text.find('|', i + 2))
          text.replace(i, 1, "\\|");
        return text;
      };
      for (const ParamSpec& p : m.params)
        s += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", p.key, cell(p.meaning), p.unit, p.default_value,
                         cell(p.allowed), p.from_fiber.empty() ? "-" : p.from_fiber);
      s += "\n";
    } else {
      s += fmt::format("{}: {}\n", m.name, m.reference);
      for (const ParamSpec& p : m.params) {
        s += fmt::format("  {:<17} {}\n", p.key, p.meaning);
        s += fmt::format("  {:<17} unit {}, default {}, allowed {}{}\n", "", p.unit.empty() ? "-" : p.unit,
                         p.default_value, p.allowed,
                         p.from_fiber.empty() ? "" : "; from a simulation: " + p.from_fiber);
      }
      s += "\n";
    }
  }
  return s;
}

}  // namespace fiberlab::analytic
