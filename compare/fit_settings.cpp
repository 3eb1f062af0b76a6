#include "compare/fit_settings.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <set>

#include "analytic/model_registry.h"
#include "common/error.h"
#include "compare/models.h"

namespace fiberlab::compare {

namespace {

struct Setting {
  std::string key, value;
};

Setting split(const std::string& kv, const std::string& flag) {
  const std::size_t eq = kv.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == kv.size())
    throw Error(fmt::format("{} {}: give KEY=VALUE (e.g. quadrature_points=524288)", flag, kv));
  return {kv.substr(0, eq), kv.substr(eq + 1)};
}

// The table keys the fit keys move (beta_long[1] and beta_long both move
// beta_long; scale_tilt moves alpha).
std::set<std::string> moved_keys(const std::string& model_name, const std::vector<std::string>& keys) {
  std::set<std::string> out;
  const analytic::ParamTable& table = analytic::model_info(model_name).params;
  for (const std::string& key : keys) {
    const std::string name = key.substr(0, key.find('['));
    for (const analytic::ParamSpec& s : table)
      if (s.key == name || s.whole_fit_key == name) out.insert(s.key);
  }
  return out;
}

}  // namespace

void check_fit_settings(const std::string& model_name, const std::vector<std::string>& settings,
                        const std::vector<std::string>& keys, const std::string& flag) {
  const analytic::ParamTable& table = analytic::model_info(model_name).params;
  const std::set<std::string> moved = moved_keys(model_name, keys);
  std::set<std::string> seen;
  analytic::ModelParameters probe = analytic::default_params(model_name);
  for (const std::string& kv : settings) {
    const Setting s = split(kv, flag);
    const analytic::ParamSpec* spec = analytic::find_param(table, s.key);
    if (!spec) {
      std::vector<std::string> all;
      for (const analytic::ParamSpec& p : table) all.push_back(p.key);
      throw Error(fmt::format("{} {}: model {} has no key '{}' (keys: {})", flag, kv, model_name, s.key,
                              fmt::join(all, ", ")));
    }
    if (!seen.insert(s.key).second) throw Error(fmt::format("{} {}: key '{}' is given twice", flag, kv, s.key));
    if (moved.count(s.key))
      throw Error(fmt::format("{} {}: '{}' is fitted (--fit): a fit-only setting must be a key the fit does "
                              "not move", flag, kv, s.key));
    if (spec->from_fiber.rfind("fiber.", 0) == 0 || spec->from_fiber.rfind("tally.", 0) == 0)
      throw Error(fmt::format("{} {}: '{}' is the simulated fiber's own ({}): fitted at another value the "
                              "fit would describe another fiber; use --set to change it everywhere",
                              flag, kv, s.key, spec->from_fiber));
    try {
      spec->set(probe, s.value);
    } catch (const Error& e) {
      throw Error(fmt::format("{} {}: {}", flag, kv, e.what()));
    }
  }
}

analytic::ModelParameters with_fit_settings(const std::string& model_name, const analytic::ModelParameters& judged,
                                            const std::vector<std::string>& settings) {
  analytic::ModelParameters out = judged;
  if (settings.empty()) return out;
  const analytic::ParamTable& table = analytic::model_info(model_name).params;
  for (const std::string& kv : settings) {
    const std::size_t eq = kv.find('=');
    analytic::find_param(table, kv.substr(0, eq))->set(out, kv.substr(eq + 1));
  }
  compare::make_model(model_name, out);  // the model's own checks
  return out;
}

void put_onto_judged(const std::string& model_name, const analytic::ModelParameters& judged, FitResult& fit) {
  fit.params = lobe_fit_start(model_name, judged, fit.keys);
  for (std::size_t j = 0; j < fit.keys.size(); ++j) set_parameter(model_name, fit.params, fit.keys[j], fit.value[j]);
}

}  // namespace fiberlab::compare
