#include "analytic/model_params.h"

#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "analytic/physical_defaults.h"
#include "common/error.h"
#include "common/physical_limits.h"
#include "common/units.h"

namespace fiberlab::analytic {

namespace param_detail {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

bool parse_double(const std::string& text, double& out) {
  const std::string t = trim(text);
  if (t.empty()) return false;
  errno = 0;
  char* end = nullptr;
  out = std::strtod(t.c_str(), &end);
  return errno == 0 && end == t.c_str() + t.size() && std::isfinite(out);
}

[[noreturn]] void fail(const std::string& key, const std::string& value, const std::string& allowed) {
  throw Error(fmt::format("--set {}={}: invalid value; allowed: {}", key, value, allowed));
}

// Degrees on the command line, radians inside.
double to_internal(const std::string& unit) { return unit == "deg" ? deg_to_rad(1.0) : 1.0; }

ParamSpec blank_spec(std::string key, std::string meaning, std::string unit, std::string default_value,
                     std::string allowed) {
  ParamSpec s;
  s.key = std::move(key);
  s.meaning = std::move(meaning);
  s.unit = std::move(unit);
  s.default_value = std::move(default_value);
  s.allowed = std::move(allowed);
  return s;
}

std::string number_text(double x) { return fmt::format("{:g}", x); }

std::string list_text(const std::vector<double>& v, double scale) {
  std::string s;
  for (double x : v) {
    if (!s.empty()) s += ',';
    s += number_text(x / scale);
  }
  return s;
}

std::vector<double> parse_list(const std::string& key, const std::string& value, const std::string& allowed,
                               const std::function<bool(double)>& ok, double scale) {
  std::vector<double> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = value.find(',', start);
    const std::string item = value.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    double x;
    if (!parse_double(item, x) || !ok(x)) fail(key, value, allowed);
    out.push_back(x * scale);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

void set_list_entry(std::vector<double>& list, int index, double value) {
  if (index < 0) {  // one common value: one entry (the last entry applies to every larger index)
    list = {value};
    return;
  }
  if (list.empty()) list.push_back(value);
  while (static_cast<int>(list.size()) <= index) list.push_back(list.back());
  list[static_cast<std::size_t>(index)] = value;
}

std::string choices_text(const std::vector<std::string>& choices) {
  std::string allowed;
  for (const auto& c : choices) allowed += (allowed.empty() ? "" : " | ") + c;
  return allowed;
}

int choice_index(const std::string& key, const std::string& value, const std::string& allowed,
                 const std::vector<std::string>& choices) {
  const std::string v = trim(value);
  for (std::size_t i = 0; i < choices.size(); ++i)
    if (v == choices[i]) return static_cast<int>(i);
  fail(key, value, allowed);
}

// ---- The shared entries' model-independent parts ------------------------------

const char* const kWidthAllowed = "a comma list of degrees in [0, 90], indexed by lobe p";
const char* const kAlphaAllowed = "a comma list of degrees in [-180, 180], indexed by lobe p";
const char* const kEccentricityAllowed = "a number in [2.2250738585072014e-308, 1]";
const char* const kAbsorptionMeaning =
    "segment attenuation: chord = exp(-sigma_a' 2 cos gamma_t) (SPEC s7, exact); published = "
    "exp(-4 sigma_a' cos^2 gamma_t) (Marschner 2003 s4.3, d'Eon 2011)";

ParamSpec eta_spec(ParamSpec s) {
  s.from_fiber = "fiber.eta";
  s.fit_min = 1.0 + 1e-6;
  // No upper end for a fit: compare/fit.h sizes its derivative steps from a
  // finite range, and (1, kMaxEta] is a bound of the arithmetic, not of the
  // fibers a fit explores.
  return s;
}

ParamSpec sigma_a_spec(ParamSpec s) {
  s.from_fiber = "fiber.sigma_a (or melanin)";
  s.fit_min = 0.0;
  return s;
}

ParamSpec lobes_spec(ParamSpec s) {
  s.from_fiber = "tally.lobes";
  return s;
}

ParamSpec width_spec(ParamSpec s) {
  // The simulator's range of a roughness width (SPEC s11): a wider Gaussian
  // spreads theta_r past the sphere of directions.
  s.from_fiber = "roughness (calibrated rule, physical_defaults.h)";
  s.per_lobe = true;
  // A fit keeps widths >= 1 deg: the published models' azimuthal
  // quadratures cost ~1/beta (d'Eon's Gaussian detector took ~5 s per
  // evaluation at 0.4 deg on a 2-direction, 18 x 36 grid), and no tally in
  // use resolves narrower lobes. --set still accepts any width >= 0.
  return fittable(s, 1.0, 90.0);
}

ParamSpec alpha_spec(ParamSpec s, std::function<const std::vector<double>&(const ModelParameters&)> get_list,
                     std::function<std::vector<double>&(ModelParameters&)> list) {
  // A shift of theta_r in [-180, 180] degrees: SPEC s7's rule gives TRT the
  // shift 4a, and a fit of scale_tilt explores the simulator's tilts
  // (-45, 45) (SPEC s11). Shifts beyond 90 deg move the lobe off the sphere
  // of directions: the model then predicts (almost) nothing there, which a
  // fit sees as a poor match, not an error.
  s.from_fiber = "fiber.scale_tilt (SPEC s7: R -2a, TT +a, TRT +4a, p >= 3: 0)";
  // As one value: the physical tilt a (TT's shift), every lobe by the rule.
  s.whole_fit_key = "scale_tilt";
  s.per_lobe = true;
  const auto get_entry = s.get_entry;
  const auto set_entry = s.set_entry;
  s.get_entry = [get_entry, get_list](const ModelParameters& p, int index) {
    return index < 0 ? rad_to_deg(for_lobe(get_list(p), 1)) : get_entry(p, index);
  };
  s.set_entry = [set_entry, list](ModelParameters& p, int index, double x) {
    if (index >= 0) return set_entry(p, index, x);
    list(p) = tilt_shifts(deg_to_rad(x));
  };
  // Free: a fit moves it through the physical tilt (fit key scale_tilt, the
  // shift rule), the range of the simulator's scale_tilt (SPEC s11).
  return fittable(s, -45.0 + 1e-6, 45.0 - 1e-6);
}

ParamSpec eccentricity_spec(ParamSpec s) {
  // The simulator's range and its reason: common/physical_limits.h.
  s.from_fiber = "fiber.eccentricity";
  s.fit_min = 1e-3;
  s.fit_max = 1.0;
  return s;
}

}  // namespace param_detail

ParamSpec fittable(ParamSpec spec, double fit_min, double fit_max) {
  spec.fit_min = fit_min;
  spec.fit_max = fit_max;
  spec.free = true;
  return spec;
}

// ---- Tables -------------------------------------------------------------------------

const ParamSpec* find_param(const ParamTable& table, const std::string& key) {
  for (const ParamSpec& s : table)
    if (s.key == key) return &s;
  return nullptr;
}

std::string key_list(const ParamTable& table) {
  std::string s;
  for (const ParamSpec& p : table) s += (s.empty() ? "" : ", ") + p.key;
  return s;
}

void apply_setting(const std::string& model_name, const ParamTable& table, ModelParameters& params,
                   const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq == std::string::npos)
    throw Error(fmt::format("--set {}: expected KEY=VALUE; allowed keys of {}: {}", key_value, model_name,
                            key_list(table)));
  const std::string key = param_detail::trim(key_value.substr(0, eq));
  const std::string value = param_detail::trim(key_value.substr(eq + 1));
  const ParamSpec* spec = find_param(table, key);
  if (!spec)
    throw Error(fmt::format("--set {}: model {} has no parameter '{}'; allowed keys: {}", key_value,
                            model_name, key, key_list(table)));
  spec->set(params, value);
}

void check_params(const std::string& model_name, const ParamTable& table, const ModelParameters& params) {
  for (const ParamSpec& spec : table)
    if (spec.in_range && !spec.in_range(params))
      throw Error(fmt::format("model {}: {} = {} is out of range; allowed: {}", model_name, spec.key,
                              spec.show(params), spec.allowed));
}

ModelParameters table_defaults(const ParamTable& table, ModelParameters blank) {
  for (const ParamSpec& s : table) s.set(blank, s.default_value);
  return blank;
}

std::string describe(const ParamTable& table, const ModelParameters& params) {
  std::string s;
  for (const ParamSpec& spec : table)
    s += fmt::format("{}{}={}", s.empty() ? "" : " ", spec.key, spec.show(params));
  return s;
}

std::vector<ParamAttribute> to_attributes(const ParamTable& table, const ModelParameters& params) {
  std::vector<ParamAttribute> out;
  for (const ParamSpec& spec : table) out.push_back(spec.attribute(params));
  return out;
}

}  // namespace fiberlab::analytic
