#pragma once
// Each model owns its parameters: a ParamTable per model (name, meaning,
// unit, default, allowed range) from which `--set KEY=VALUE` parsing and
// checking, the defaults, `fiberlab models` / `--help`, the README section
// and the attributes of a prediction file all come. The tables themselves
// live with their models (exact_params() in smooth_cylinder.cpp, ...) and are
// listed in model_registry.cpp.
//
// The values are held in ModelParams (model.h), a plain bag of fields that
// the model code reads; a table says which of those fields its model uses.
// A key that is not in the model's table is refused.
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "analytic/model.h"

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
  // Parse `value` (command-line units: degrees for angles) into params.
  // Throws fiberlab::Error "--set KEY=VALUE: invalid value; allowed: ...".
  std::function<void(ModelParams&, const std::string& value)> set;
  // The current value, in command-line units (degrees), as text.
  std::function<std::string(const ModelParams&)> show;
  // Whether the current value is in the allowed range: `set` checks text,
  // this checks values that came another way (a simulation's fiber, a fit,
  // an atlas config), in check_params().
  std::function<bool(const ModelParams&)> in_range;
  // The current value for files (radians).
  std::function<ParamAttribute(const ModelParams&)> attribute;
  // Fitting (compare/fit.h): the value as a number in command-line units
  // (degrees), read and written without the text round trip. Scalars
  // (number_param): get_number / set_number. Lists (list_param): entry
  // `index` (the list extended by its last entry as needed), or with index
  // -1 the list as one common value (get: entry 0; set: every entry).
  std::function<double(const ModelParams&)> get_number;
  std::function<void(ModelParams&, double)> set_number;
  std::function<double(const ModelParams&, int index)> get_entry;
  std::function<void(ModelParams&, int index, double)> set_entry;
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

// Builders for the usual kinds of parameter; `field` is the ModelParams
// member the key sets. Angles (unit "deg") are degrees on the command line,
// radians in ModelParams and in files.
ParamSpec number_param(std::string key, std::string meaning, std::string unit,
                       std::string default_value, std::string allowed, double ModelParams::*field,
                       std::function<bool(double)> ok);
// A comma list indexed by lobe p (or channel), the last entry for every larger p.
ParamSpec list_param(std::string key, std::string meaning, std::string unit,
                     std::string default_value, std::string allowed,
                     std::vector<double> ModelParams::*field, std::function<bool(double)> ok);
ParamSpec integer_param(std::string key, std::string meaning, std::string default_value,
                        int ModelParams::*field, int min_value);
// One of `choices`; `set(params, i)` stores choice i, `get(params)` returns it.
ParamSpec choice_param(std::string key, std::string meaning, std::string default_value,
                       std::vector<std::string> choices,
                       std::function<void(ModelParams&, int)> set,
                       std::function<int(const ModelParams&)> get);

// Parameters shared by several models (one definition each).
ParamSpec eta_param();
ParamSpec sigma_a_param();
ParamSpec lobes_param();
ParamSpec beta_long_param(std::string meaning);
ParamSpec beta_azim_param(std::string meaning);
ParamSpec alpha_param(std::string meaning);
// eccentricity in [kMinEccentricity, 1] (common/physical_limits.h), as the simulator's.
ParamSpec eccentricity_param();
ParamSpec absorption_param(std::string default_value);

// The spec of `key` in `table`, or nullptr.
const ParamSpec* find_param(const ParamTable& table, const std::string& key);

// Applies "KEY=VALUE" for the model `model_name` with table `table`. A key
// not in the table: fiberlab::Error naming the key, the model and its keys.
void apply_setting(const std::string& model_name, const ParamTable& table, ModelParams& params,
                   const std::string& key_value);

// Every parameter of `params` in its table's range; otherwise fiberlab::Error
// "model NAME: KEY = VALUE is out of range; allowed: ...". make_model() calls
// it, so that no model is built from a value --set would refuse.
void check_params(const std::string& model_name, const ParamTable& table, const ModelParams& params);

// The table's defaults applied to a ModelParams.
ModelParams table_defaults(const ParamTable& table);

// "key=value key=value ..." of every parameter in the table (command-line units).
std::string describe(const ParamTable& table, const ModelParams& params);
// Every parameter of the table, for files.
std::vector<ParamAttribute> to_attributes(const ParamTable& table, const ModelParams& params);
// The keys of a table, comma separated.
std::string key_list(const ParamTable& table);

}  // namespace fiberlab::analytic
