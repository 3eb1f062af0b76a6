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

namespace {

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

}  // namespace

ParamSpec number_param(std::string key, std::string meaning, std::string unit,
                       std::string default_value, std::string allowed, double ModelParams::*field,
                       std::function<bool(double)> ok) {
  const double scale = to_internal(unit);
  ParamSpec s = blank_spec(key, std::move(meaning), unit, std::move(default_value), allowed);
  s.set = [key, allowed, field, ok, scale](ModelParams& p, const std::string& value) {
    double x;
    if (!parse_double(value, x) || !ok(x)) fail(key, value, allowed);
    p.*field = x * scale;
  };
  s.show = [field, scale](const ModelParams& p) { return number_text(p.*field / scale); };
  s.in_range = [field, ok, scale](const ModelParams& p) {
    const double x = p.*field / scale;
    return std::isfinite(x) && ok(x);
  };
  s.attribute = [key, field](const ModelParams& p) { return ParamAttribute{key, false, "", {p.*field}}; };
  s.get_number = [field, scale](const ModelParams& p) { return p.*field / scale; };
  s.set_number = [field, scale](ModelParams& p, double x) { p.*field = x * scale; };
  return s;
}

ParamSpec fittable(ParamSpec spec, double fit_min, double fit_max) {
  spec.fit_min = fit_min;
  spec.fit_max = fit_max;
  spec.free = true;
  return spec;
}

ParamSpec list_param(std::string key, std::string meaning, std::string unit,
                     std::string default_value, std::string allowed,
                     std::vector<double> ModelParams::*field, std::function<bool(double)> ok) {
  const double scale = to_internal(unit);
  ParamSpec s = blank_spec(key, std::move(meaning), unit, std::move(default_value), allowed);
  s.set = [key, allowed, field, ok, scale](ModelParams& p, const std::string& value) {
    std::vector<double> out;
    std::size_t start = 0;
    while (true) {
      const auto comma = value.find(',', start);
      const std::string item =
          value.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      double x;
      if (!parse_double(item, x) || !ok(x)) fail(key, value, allowed);
      out.push_back(x * scale);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    p.*field = out;
  };
  s.show = [field, scale](const ModelParams& p) { return list_text(p.*field, scale); };
  s.in_range = [field, ok, scale](const ModelParams& p) {
    if ((p.*field).empty()) return false;
    for (double v : p.*field)
      if (!std::isfinite(v / scale) || !ok(v / scale)) return false;
    return true;
  };
  s.attribute = [key, field](const ModelParams& p) { return ParamAttribute{key, false, "", p.*field}; };
  s.get_entry = [field, scale](const ModelParams& p, int index) { return for_lobe(p.*field, std::max(0, index)) / scale; };
  s.set_entry = [field, scale](ModelParams& p, int index, double x) {
    std::vector<double>& list = p.*field;
    if (index < 0) {  // one common value: one entry (the last entry applies to every larger index)
      list = {x * scale};
      return;
    }
    if (list.empty()) list.push_back(x * scale);
    while (static_cast<int>(list.size()) <= index) list.push_back(list.back());
    list[static_cast<std::size_t>(index)] = x * scale;
  };
  return s;
}

ParamSpec integer_param(std::string key, std::string meaning, std::string default_value,
                        int ModelParams::*field, int min_value) {
  const std::string allowed = fmt::format("an integer >= {}", min_value);
  ParamSpec s = blank_spec(key, std::move(meaning), "integer", std::move(default_value), allowed);
  s.set = [key, allowed, field, min_value](ModelParams& p, const std::string& value) {
    double x;
    if (!parse_double(value, x) || x != std::floor(x) || x < min_value || x > 1e6)
      fail(key, value, allowed);
    p.*field = static_cast<int>(x);
  };
  s.show = [field](const ModelParams& p) { return std::to_string(p.*field); };
  s.in_range = [field, min_value](const ModelParams& p) { return p.*field >= min_value && p.*field <= 1e6; };
  s.attribute = [key, field](const ModelParams& p) {
    return ParamAttribute{key, false, "", {static_cast<double>(p.*field)}};
  };
  return s;
}

ParamSpec choice_param(std::string key, std::string meaning, std::string default_value,
                       std::vector<std::string> choices, std::function<void(ModelParams&, int)> set,
                       std::function<int(const ModelParams&)> get) {
  std::string allowed;
  for (const auto& c : choices) allowed += (allowed.empty() ? "" : " | ") + c;
  ParamSpec s = blank_spec(key, std::move(meaning), "choice", std::move(default_value), allowed);
  s.set = [key, allowed, choices, set](ModelParams& p, const std::string& value) {
    const std::string v = trim(value);
    for (std::size_t i = 0; i < choices.size(); ++i)
      if (v == choices[i]) return set(p, static_cast<int>(i));
    fail(key, value, allowed);
  };
  s.show = [choices, get](const ModelParams& p) { return choices.at(get(p)); };
  s.in_range = [n = choices.size(), get](const ModelParams& p) {
    return get(p) >= 0 && static_cast<std::size_t>(get(p)) < n;
  };
  s.attribute = [key, choices, get](const ModelParams& p) {
    return ParamAttribute{key, true, choices.at(get(p)), {}};
  };
  return s;
}

// ---- Shared parameters ----------------------------------------------------------

ParamSpec eta_param() {
  // The simulator's bound and its reason: common/physical_limits.h.
  ParamSpec s = number_param("eta", "refractive index of the fiber relative to the medium", "", "1.55",
                             "a number in (1, 1e9]", &ModelParams::eta,
                             [](double x) { return x > 1.0 && x <= kMaxEta; });
  s.from_fiber = "fiber.eta";
  s.fit_min = 1.0 + 1e-6;
  // No upper end for a fit: compare/fit.h sizes its derivative steps from a
  // finite range, and (1, kMaxEta] is a bound of the arithmetic, not of the
  // fibers a fit explores.
  return s;
}

ParamSpec sigma_a_param() {
  ParamSpec s = list_param("sigma_a", "absorption coefficient per channel", "1/R", "0,0,0",
                           "a comma list of numbers >= 0, one per channel", &ModelParams::sigma_a,
                           [](double x) { return x >= 0.0; });
  s.from_fiber = "fiber.sigma_a (or melanin)";
  s.fit_min = 0.0;
  // One common value for every channel keeps the number of channels.
  const auto set_entry = s.set_entry;
  s.set_entry = [set_entry](ModelParams& p, int index, double x) {
    if (index >= 0) return set_entry(p, index, x);
    std::fill(p.sigma_a.begin(), p.sigma_a.end(), x);
  };
  return s;
}

ParamSpec lobes_param() {
  ParamSpec s = integer_param("lobes", "tally lobes: 0..L-2 one order p each, L-1 every larger p", "4",
                              &ModelParams::lobes, 1);
  s.from_fiber = "tally.lobes";
  return s;
}

ParamSpec beta_long_param(std::string meaning) {
  // The simulator's range of a roughness width (SPEC s11): a wider Gaussian
  // spreads theta_r past the sphere of directions.
  ParamSpec s = list_param("beta_long", std::move(meaning), "deg", "0",
                           "a comma list of degrees in [0, 90], indexed by lobe p", &ModelParams::beta_long,
                           [](double x) { return x >= 0.0 && x <= 90.0; });
  s.from_fiber = "roughness (calibrated rule, physical_defaults.h)";
  s.per_lobe = true;
  // A fit keeps widths >= 1 deg: the published models' azimuthal
  // quadratures cost ~1/beta (d'Eon's Gaussian detector took ~5 s per
  // evaluation at 0.4 deg on a 2-direction, 18 x 36 grid), and no tally in
  // use resolves narrower lobes. --set still accepts any width >= 0.
  return fittable(s, 1.0, 90.0);
}

ParamSpec beta_azim_param(std::string meaning) {
  // The simulator's range of a roughness width (SPEC s11): a wider Gaussian
  // spreads theta_r past the sphere of directions.
  ParamSpec s = list_param("beta_azim", std::move(meaning), "deg", "0",
                           "a comma list of degrees in [0, 90], indexed by lobe p", &ModelParams::beta_azim,
                           [](double x) { return x >= 0.0 && x <= 90.0; });
  s.from_fiber = "roughness (calibrated rule, physical_defaults.h)";
  s.per_lobe = true;
  // A fit keeps widths >= 1 deg: the published models' azimuthal
  // quadratures cost ~1/beta (d'Eon's Gaussian detector took ~5 s per
  // evaluation at 0.4 deg on a 2-direction, 18 x 36 grid), and no tally in
  // use resolves narrower lobes. --set still accepts any width >= 0.
  return fittable(s, 1.0, 90.0);
}

ParamSpec alpha_param(std::string meaning) {
  // A shift of theta_r in [-180, 180] degrees: SPEC s7's rule gives TRT the
  // shift 4a, and a fit of scale_tilt explores the simulator's tilts
  // (-45, 45) (SPEC s11). Shifts beyond 90 deg move the lobe off the sphere
  // of directions: the model then predicts (almost) nothing there, which a
  // fit sees as a poor match, not an error.
  ParamSpec s = list_param("alpha", std::move(meaning), "deg", "0",
                           "a comma list of degrees in [-180, 180], indexed by lobe p", &ModelParams::alpha,
                           [](double x) { return std::abs(x) <= 180.0; });
  s.from_fiber = "fiber.scale_tilt (SPEC s7: R -2a, TT +a, TRT +4a, p >= 3: 0)";
  // As one value: the physical tilt a (TT's shift), every lobe by the rule.
  s.whole_fit_key = "scale_tilt";
  s.per_lobe = true;
  const auto get_entry = s.get_entry;
  const auto set_entry = s.set_entry;
  s.get_entry = [get_entry](const ModelParams& p, int index) {
    return index < 0 ? rad_to_deg(for_lobe(p.alpha, 1)) : get_entry(p, index);
  };
  s.set_entry = [set_entry](ModelParams& p, int index, double x) {
    if (index >= 0) return set_entry(p, index, x);
    p.alpha = tilt_shifts(deg_to_rad(x));
  };
  // Free: a fit moves it through the physical tilt (fit key scale_tilt, the
  // shift rule), the range of the simulator's scale_tilt (SPEC s11).
  return fittable(s, -45.0 + 1e-6, 45.0 - 1e-6);
}

ParamSpec eccentricity_param() {
  // The simulator's range and its reason: common/physical_limits.h.
  ParamSpec s = number_param("eccentricity", "minor/major axis ratio of the cross-section", "", "1",
                             "a number in [2.2250738585072014e-308, 1]", &ModelParams::eccentricity,
                             [](double x) { return x >= kMinEccentricity && x <= 1.0; });
  s.from_fiber = "fiber.eccentricity";
  s.fit_min = 1e-3;
  s.fit_max = 1.0;
  return s;
}

ParamSpec absorption_param(std::string default_value) {
  return choice_param(
      "absorption",
      "segment attenuation: chord = exp(-sigma_a' 2 cos gamma_t) (SPEC s7, exact); published = "
      "exp(-4 sigma_a' cos^2 gamma_t) (Marschner 2003 s4.3, d'Eon 2011)",
      std::move(default_value), {"published", "chord"},
      [](ModelParams& p, int i) { p.absorption = i == 1 ? Absorption::Chord : Absorption::Published; },
      [](const ModelParams& p) { return p.absorption == Absorption::Chord ? 1 : 0; });
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

void apply_setting(const std::string& model_name, const ParamTable& table, ModelParams& params,
                   const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq == std::string::npos)
    throw Error(fmt::format("--set {}: expected KEY=VALUE; allowed keys of {}: {}", key_value, model_name,
                            key_list(table)));
  const std::string key = trim(key_value.substr(0, eq)), value = trim(key_value.substr(eq + 1));
  const ParamSpec* spec = find_param(table, key);
  if (!spec)
    throw Error(fmt::format("--set {}: model {} has no parameter '{}'; allowed keys: {}", key_value,
                            model_name, key, key_list(table)));
  spec->set(params, value);
}

void check_params(const std::string& model_name, const ParamTable& table, const ModelParams& params) {
  for (const ParamSpec& spec : table)
    if (spec.in_range && !spec.in_range(params))
      throw Error(fmt::format("model {}: {} = {} is out of range; allowed: {}", model_name, spec.key,
                              spec.show(params), spec.allowed));
}

ModelParams table_defaults(const ParamTable& table) {
  ModelParams p;
  for (const ParamSpec& s : table) s.set(p, s.default_value);
  return p;
}

std::string describe(const ParamTable& table, const ModelParams& params) {
  std::string s;
  for (const ParamSpec& spec : table)
    s += fmt::format("{}{}={}", s.empty() ? "" : " ", spec.key, spec.show(params));
  return s;
}

std::vector<ParamAttribute> to_attributes(const ParamTable& table, const ModelParams& params) {
  std::vector<ParamAttribute> out;
  for (const ParamSpec& spec : table) out.push_back(spec.attribute(params));
  return out;
}

}  // namespace fiberlab::analytic
