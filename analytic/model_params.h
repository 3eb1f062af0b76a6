#pragma once
// Each model owns its parameters: a parameter struct of its own (beside the
// model: Deon2011Params in deon2011.h, ...) and a ParamTable (name, meaning,
// unit, default, allowed range) whose entries bind to that struct's fields.
// `--set KEY=VALUE` parsing and checking, the defaults, `fiberlab models` /
// `--help`, the README section, the attributes of a prediction file and the
// fit's accessors all come from the table. The tables live with their
// models and are listed in model_registry.cpp.
//
// The entries take the values as a ModelParameters (model_parameters.h)
// holding the model's struct; the builders below are templates over that
// struct. A key that is not in the model's table is refused.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "analytic/model.h"
#include "analytic/model_parameters.h"
#include "common/physical_limits.h"

namespace fiberlab::analytic {

// A parameter as written to a file: text, or numbers (angles in radians).
struct ParamAttribute {
  std::string name;
  bool is_text = false;
  std::string text;
  std::vector<double> numbers;
};

struct ParamSpec {
  std::string key;            // the --set name
  std::string meaning;        // one line
  std::string unit;           // "deg", "1/R", "" (unitless), "integer", "choice"
  std::string default_value;  // as on the command line; what the model uses unless told
  std::string allowed;        // the allowed values, for errors and listings
  // Where a simulation's config sets it (empty: only the table's default).
  std::string from_fiber;
  // Parse `value` (command-line units: degrees for angles) into the model's struct.
  // Throws fiberlab::Error "--set KEY=VALUE: invalid value; allowed: ...".
  std::function<void(ModelParameters&, const std::string& value)> set;
  // The current value, in command-line units (degrees), as text.
  std::function<std::string(const ModelParameters&)> show;
  // Whether the current value is in the allowed range: `set` checks text,
  // this checks values that came another way (a simulation's fiber, a fit,
  // an atlas config), in check_params().
  std::function<bool(const ModelParameters&)> in_range;
  // The current value for files (radians).
  std::function<ParamAttribute(const ModelParameters&)> attribute;
  // Fitting (compare/fit.h): the value as a number in command-line units
  // (degrees), read and written without the text round trip. Scalars
  // (number_param): get_number / set_number. Lists (list_param): entry
  // `index` (the list extended by its last entry as needed), or with index
  // -1 the list as one common value (get: entry 0; set: every entry).
  std::function<double(const ModelParameters&)> get_number;
  std::function<void(ModelParameters&, double)> set_number;
  std::function<double(const ModelParameters&, int index)> get_entry;
  std::function<void(ModelParameters&, int index, double)> set_entry;
  // The fit key of a list as one value when it is not the list's own key
  // (alpha: `scale_tilt`, the physical tilt through SPEC s7's shift rule;
  // a bare `alpha` is refused). Empty: the key itself.
  std::string whole_fit_key;
  // A list indexed by the tally's lobe (beta_long, beta_azim, alpha): a
  // per-lobe fit moves that lobe's entry (compare/fit.h per_lobe_keys()).
  bool per_lobe = false;
  // The closed range a fit keeps the value in, in command-line units: the
  // table's allowed range, an open end moved inside by a small margin
  // (eta > 1: 1 + 1e-6, the one floor of eta: a fit never asks for less,
  // and no model needs more). For a list, the range of each entry.
  double fit_min = -std::numeric_limits<double>::infinity();
  double fit_max = std::numeric_limits<double>::infinity();
  // A free parameter: part of the model's shape that the fiber's physics
  // does not fix (roughness widths, scale tilt, ...), as opposed to eta,
  // sigma_a or the lobe count. `fiberlab atlas` fits every free parameter
  // of every model (compare/fit.h, free_fit_keys()).
  bool free = false;
};

// Sets the fit range and marks the parameter free (table entries read as
// `fittable(number_param(...), 0, 1)`).
ParamSpec fittable(ParamSpec spec, double fit_min, double fit_max);

using ParamTable = std::vector<ParamSpec>;

// ---- Builders ---------------------------------------------------------------
// Each binds a key to a field of the model's struct S (a member pointer).
// Angles (unit "deg") are degrees on the command line, radians in the struct
// and in files.

namespace param_detail {
// Shared by the templates below (model_params.cpp).
bool parse_double(const std::string& text, double& out);
std::string trim(const std::string& s);
[[noreturn]] void fail(const std::string& key, const std::string& value, const std::string& allowed);
double to_internal(const std::string& unit);  // radians per command-line unit
ParamSpec blank_spec(std::string key, std::string meaning, std::string unit, std::string default_value,
                     std::string allowed);
std::string number_text(double x);
std::string list_text(const std::vector<double>& v, double scale);
std::vector<double> parse_list(const std::string& key, const std::string& value, const std::string& allowed,
                               const std::function<bool(double)>& ok, double scale);
void set_list_entry(std::vector<double>& list, int index, double value);
std::string choices_text(const std::vector<std::string>& choices);
int choice_index(const std::string& key, const std::string& value, const std::string& allowed,
                 const std::vector<std::string>& choices);
}  // namespace param_detail

// A number (double, or an integer type read as a number: huang2022's
// quadrature_points).
template <class S, class T>
ParamSpec number_param(std::string key, std::string meaning, std::string unit, std::string default_value,
                       std::string allowed, T S::*field, std::function<bool(double)> ok) {
  static_assert(std::is_arithmetic_v<T>);
  using namespace param_detail;
  const double scale = to_internal(unit);
  ParamSpec s = blank_spec(key, std::move(meaning), unit, std::move(default_value), allowed);
  s.set = [key, allowed, field, ok, scale](ModelParameters& p, const std::string& value) {
    double x;
    if (!parse_double(value, x) || !ok(x)) fail(key, value, allowed);
    p.as<S>().*field = static_cast<T>(x * scale);
  };
  s.show = [field, scale](const ModelParameters& p) {
    return number_text(static_cast<double>(p.as<S>().*field) / scale);
  };
  s.in_range = [field, ok, scale](const ModelParameters& p) {
    const double x = static_cast<double>(p.as<S>().*field) / scale;
    return std::isfinite(x) && ok(x);
  };
  s.attribute = [key, field](const ModelParameters& p) {
    return ParamAttribute{key, false, "", {static_cast<double>(p.as<S>().*field)}};
  };
  s.get_number = [field, scale](const ModelParameters& p) { return static_cast<double>(p.as<S>().*field) / scale; };
  s.set_number = [field, scale](ModelParameters& p, double x) { p.as<S>().*field = static_cast<T>(x * scale); };
  return s;
}

// A comma list indexed by lobe p (or channel), the last entry for every larger p.
template <class S>
ParamSpec list_param(std::string key, std::string meaning, std::string unit, std::string default_value,
                     std::string allowed, std::vector<double> S::*field, std::function<bool(double)> ok) {
  using namespace param_detail;
  const double scale = to_internal(unit);
  ParamSpec s = blank_spec(key, std::move(meaning), unit, std::move(default_value), allowed);
  s.set = [key, allowed, field, ok, scale](ModelParameters& p, const std::string& value) {
    p.as<S>().*field = parse_list(key, value, allowed, ok, scale);
  };
  s.show = [field, scale](const ModelParameters& p) { return list_text(p.as<S>().*field, scale); };
  s.in_range = [field, ok, scale](const ModelParameters& p) {
    const std::vector<double>& list = p.as<S>().*field;
    if (list.empty()) return false;
    for (double v : list)
      if (!std::isfinite(v / scale) || !ok(v / scale)) return false;
    return true;
  };
  s.attribute = [key, field](const ModelParameters& p) { return ParamAttribute{key, false, "", p.as<S>().*field}; };
  s.get_entry = [field, scale](const ModelParameters& p, int index) {
    return for_lobe(p.as<S>().*field, index < 0 ? 0 : index) / scale;
  };
  s.set_entry = [field, scale](ModelParameters& p, int index, double x) {
    set_list_entry(p.as<S>().*field, index, x * scale);
  };
  return s;
}

template <class S>
ParamSpec integer_param(std::string key, std::string meaning, std::string default_value, int S::*field,
                        int min_value) {
  using namespace param_detail;
  const std::string allowed = "an integer >= " + std::to_string(min_value);
  ParamSpec s = blank_spec(key, std::move(meaning), "integer", std::move(default_value), allowed);
  s.set = [key, allowed, field, min_value](ModelParameters& p, const std::string& value) {
    double x;
    if (!parse_double(value, x) || x != std::floor(x) || x < min_value || x > 1e6) fail(key, value, allowed);
    p.as<S>().*field = static_cast<int>(x);
  };
  s.show = [field](const ModelParameters& p) { return std::to_string(p.as<S>().*field); };
  s.in_range = [field, min_value](const ModelParameters& p) {
    const int x = p.as<S>().*field;
    return x >= min_value && x <= 1e6;
  };
  s.attribute = [key, field](const ModelParameters& p) {
    return ParamAttribute{key, false, "", {static_cast<double>(p.as<S>().*field)}};
  };
  return s;
}

// One of `choices`; `set(params, i)` stores choice i in the struct S,
// `get(params)` returns it.
template <class S>
ParamSpec choice_param(std::string key, std::string meaning, std::string default_value,
                       std::vector<std::string> choices, std::function<void(S&, int)> set,
                       std::function<int(const S&)> get) {
  using namespace param_detail;
  const std::string allowed = choices_text(choices);
  ParamSpec s = blank_spec(key, std::move(meaning), "choice", std::move(default_value), allowed);
  s.set = [key, allowed, choices, set](ModelParameters& p, const std::string& value) {
    set(p.as<S>(), choice_index(key, value, allowed, choices));
  };
  s.show = [choices, get](const ModelParameters& p) { return choices.at(get(p.as<S>())); };
  s.in_range = [n = choices.size(), get](const ModelParameters& p) {
    const int i = get(p.as<S>());
    return i >= 0 && static_cast<std::size_t>(i) < n;
  };
  s.attribute = [key, choices, get](const ModelParameters& p) {
    return ParamAttribute{key, true, choices.at(get(p.as<S>())), {}};
  };
  return s;
}

// An enum field whose values 0, 1, ... are `choices` in order.
template <class S, class E>
ParamSpec enum_param(std::string key, std::string meaning, std::string default_value,
                     std::vector<std::string> choices, E S::*field) {
  static_assert(std::is_enum_v<E>);
  return choice_param<S>(
      std::move(key), std::move(meaning), std::move(default_value), std::move(choices),
      [field](S& p, int i) { p.*field = static_cast<E>(i); },
      [field](const S& p) { return static_cast<int>(p.*field); });
}

// A bool field: `choices` = {the choice for false, the choice for true}.
template <class S>
ParamSpec bool_param(std::string key, std::string meaning, std::string default_value,
                     std::vector<std::string> choices, bool S::*field) {
  return choice_param<S>(
      std::move(key), std::move(meaning), std::move(default_value), std::move(choices),
      [field](S& p, int i) { p.*field = i == 1; }, [field](const S& p) { return p.*field ? 1 : 0; });
}

// ---- Parameters shared by several models (one definition each) -----------------
// S must have the field the key names (eta, sigma_a, lobes, beta_long,
// beta_azim, alpha, eccentricity, absorption).

namespace param_detail {
// The parts of the shared entries that do not depend on S (model_params.cpp).
ParamSpec eta_spec(ParamSpec bound);
ParamSpec sigma_a_spec(ParamSpec bound);
ParamSpec lobes_spec(ParamSpec bound);
ParamSpec width_spec(ParamSpec bound);
ParamSpec alpha_spec(ParamSpec bound, std::function<const std::vector<double>&(const ModelParameters&)> get_list,
                     std::function<std::vector<double>&(ModelParameters&)> list);
ParamSpec eccentricity_spec(ParamSpec bound);
extern const char* const kWidthAllowed;
extern const char* const kAlphaAllowed;
extern const char* const kEccentricityAllowed;
extern const char* const kAbsorptionMeaning;
}  // namespace param_detail

template <class S>
ParamSpec eta_param() {
  // The simulator's bound and its reason: common/physical_limits.h.
  return param_detail::eta_spec(number_param("eta", "refractive index of the fiber relative to the medium", "",
                                             "1.55", "a number in (1, 1e9]", &S::eta,
                                             [](double x) { return x > 1.0 && x <= kMaxEta; }));
}

template <class S>
ParamSpec sigma_a_param() {
  ParamSpec s = param_detail::sigma_a_spec(
      list_param("sigma_a", "absorption coefficient per channel", "1/R", "0,0,0",
                 "a comma list of numbers >= 0, one per channel", &S::sigma_a, [](double x) { return x >= 0.0; }));
  // One common value for every channel keeps the number of channels.
  const auto set_entry = s.set_entry;
  s.set_entry = [set_entry](ModelParameters& p, int index, double x) {
    if (index >= 0) return set_entry(p, index, x);
    std::vector<double>& list = p.as<S>().sigma_a;
    std::fill(list.begin(), list.end(), x);
  };
  return s;
}

template <class S>
ParamSpec lobes_param() {
  return param_detail::lobes_spec(
      integer_param("lobes", "tally lobes: 0..L-2 one order p each, L-1 every larger p", "4", &S::lobes, 1));
}

template <class S>
ParamSpec beta_long_param(std::string meaning) {
  return param_detail::width_spec(list_param("beta_long", std::move(meaning), "deg", "0",
                                             param_detail::kWidthAllowed, &S::beta_long,
                                             [](double x) { return x >= 0.0 && x <= 90.0; }));
}

template <class S>
ParamSpec beta_azim_param(std::string meaning) {
  return param_detail::width_spec(list_param("beta_azim", std::move(meaning), "deg", "0",
                                             param_detail::kWidthAllowed, &S::beta_azim,
                                             [](double x) { return x >= 0.0 && x <= 90.0; }));
}

template <class S>
ParamSpec alpha_param(std::string meaning) {
  return param_detail::alpha_spec(
      list_param("alpha", std::move(meaning), "deg", "0", param_detail::kAlphaAllowed, &S::alpha,
                 [](double x) { return std::abs(x) <= 180.0; }),
      [](const ModelParameters& p) -> const std::vector<double>& { return p.as<S>().alpha; },
      [](ModelParameters& p) -> std::vector<double>& { return p.as<S>().alpha; });
}

// eccentricity in [kMinEccentricity, 1] (common/physical_limits.h), as the simulator's.
template <class S>
ParamSpec eccentricity_param() {
  return param_detail::eccentricity_spec(
      number_param("eccentricity", "minor/major axis ratio of the cross-section", "", "1",
                   param_detail::kEccentricityAllowed, &S::eccentricity,
                   [](double x) { return x >= kMinEccentricity && x <= 1.0; }));
}

template <class S>
ParamSpec absorption_param(std::string default_value) {
  return enum_param("absorption", param_detail::kAbsorptionMeaning, std::move(default_value),
                    {"published", "chord"}, &S::absorption);
}

// The spec of `key` in `table`, or nullptr.
const ParamSpec* find_param(const ParamTable& table, const std::string& key);

// Applies "KEY=VALUE" for the model `model_name` with table `table`. A key
// not in the table: fiberlab::Error naming the key, the model and its keys.
void apply_setting(const std::string& model_name, const ParamTable& table, ModelParameters& params,
                   const std::string& key_value);

// Every parameter of `params` in its table's range; otherwise fiberlab::Error
// "model NAME: KEY = VALUE is out of range; allowed: ...". make_model() calls
// it, so that no model is built from a value --set would refuse.
void check_params(const std::string& model_name, const ParamTable& table, const ModelParameters& params);

// The table's defaults applied to `blank` (the model's struct as constructed).
ModelParameters table_defaults(const ParamTable& table, ModelParameters blank);

// "key=value key=value ..." of every parameter in the table (command-line units).
std::string describe(const ParamTable& table, const ModelParameters& params);
// Every parameter of the table, for files.
std::vector<ParamAttribute> to_attributes(const ParamTable& table, const ModelParameters& params);
// The keys of a table, comma separated.
std::string key_list(const ParamTable& table);

}  // namespace fiberlab::analytic
