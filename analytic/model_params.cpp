#include "analytic/model_params.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>

#include "common/error.h"
#include "common/units.h"

namespace fiberlab::analytic {

namespace {

const char* kKeys =
    "eta, sigma_a, beta_long, beta_azim, alpha, absorption, longitudinal, roots, eccentricity, "
    "k_g, w_c, delta_eta, delta_h_m, lobes, quadrature_order, r_fresnel, max_order, n_theta_d";

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

double number(const std::string& key, const std::string& value, const std::string& allowed,
              const std::function<bool(double)>& ok) {
  double x;
  if (!parse_double(value, x) || !ok(x)) fail(key, value, allowed);
  return x;
}

std::vector<double> list(const std::string& key, const std::string& value,
                         const std::string& allowed, const std::function<bool(double)>& ok,
                         double scale) {
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

int integer(const std::string& key, const std::string& value, const std::string& allowed) {
  double x;
  if (!parse_double(value, x) || x != std::floor(x) || x < 1 || x > 1e6) fail(key, value, allowed);
  return static_cast<int>(x);
}

}  // namespace

void apply_setting(ModelParams& p, const std::string& key_value) {
  const auto eq = key_value.find('=');
  if (eq == std::string::npos)
    throw Error(fmt::format("--set {}: expected KEY=VALUE; allowed keys: {}", key_value, kKeys));
  const std::string key = trim(key_value.substr(0, eq)), value = trim(key_value.substr(eq + 1));
  const double deg = deg_to_rad(1.0);
  auto nonneg = [](double x) { return x >= 0.0; };
  auto any = [](double) { return true; };
  if (key == "eta") {
    p.eta = number(key, value, "a number > 1", [](double x) { return x > 1.0; });
  } else if (key == "sigma_a") {
    p.sigma_a = list(key, value, "a comma list of numbers >= 0 (1/R per channel)", nonneg, 1.0);
  } else if (key == "beta_long") {
    p.beta_long = list(key, value, "a comma list of degrees >= 0, indexed by p", nonneg, deg);
  } else if (key == "beta_azim") {
    p.beta_azim = list(key, value, "a comma list of degrees >= 0, indexed by p", nonneg, deg);
  } else if (key == "alpha") {
    p.alpha = list(key, value, "a comma list of degrees, indexed by p", any, deg);
  } else if (key == "absorption") {
    if (value == "published") p.absorption = Absorption::Published;
    else if (value == "chord") p.absorption = Absorption::Chord;
    else fail(key, value, "published | chord");
  } else if (key == "longitudinal") {
    if (value == "theta_h") p.two_theta_h = false;
    else if (value == "two_theta_h") p.two_theta_h = true;
    else fail(key, value, "theta_h | two_theta_h");
  } else if (key == "roots") {
    if (value == "cubic") p.exact_roots = false;
    else if (value == "exact") p.exact_roots = true;
    else fail(key, value, "cubic | exact");
  } else if (key == "eccentricity") {
    p.eccentricity = number(key, value, "a number in (0, 1]", [](double x) { return x > 0.0 && x <= 1.0; });
  } else if (key == "k_g") {
    p.k_g = number(key, value, "a number >= 0", nonneg);
  } else if (key == "w_c") {
    p.w_c = number(key, value, "degrees >= 0", nonneg) * deg;
  } else if (key == "delta_eta") {
    p.delta_eta = number(key, value, "a number >= 0 (unitless)", nonneg);
  } else if (key == "delta_h_m") {
    p.delta_h_m = number(key, value, "a number >= 0 (unitless, in h)", nonneg);
  } else if (key == "lobes") {
    p.lobes = integer(key, value, "an integer >= 1");
  } else if (key == "quadrature_order") {
    p.quadrature_order = integer(key, value, "an integer >= 1");
  } else if (key == "n_theta_d") {
    if (value == "exit") p.specular_theta_d = false;
    else if (value == "specular") p.specular_theta_d = true;
    else fail(key, value, "exit | specular");
  } else if (key == "max_order") {
    p.max_order = integer(key, value, "an integer >= 1");
  } else if (key == "r_fresnel") {
    if (value == "half_angle") p.r_half_angle_fresnel = true;
    else if (value == "per_h") p.r_half_angle_fresnel = false;
    else fail(key, value, "half_angle | per_h");
  } else {
    throw Error(fmt::format("--set {}: unknown key; allowed: {}", key, kKeys));
  }
}

void apply_settings(ModelParams& params, const std::vector<std::string>& key_values) {
  for (const auto& kv : key_values) apply_setting(params, kv);
}

std::vector<ParamAttribute> to_attributes(const ModelParams& p) {
  auto num = [](std::string n, std::vector<double> v) { return ParamAttribute{std::move(n), false, "", std::move(v)}; };
  auto txt = [](std::string n, std::string t) { return ParamAttribute{std::move(n), true, std::move(t), {}}; };
  return {
      num("eta", {p.eta}),
      num("sigma_a", p.sigma_a),
      num("beta_long", p.beta_long),
      num("beta_azim", p.beta_azim),
      num("alpha", p.alpha),
      txt("absorption", p.absorption == Absorption::Chord ? "chord" : "published"),
      txt("longitudinal", p.two_theta_h ? "two_theta_h" : "theta_h"),
      txt("roots", p.exact_roots ? "exact" : "cubic"),
      num("eccentricity", {p.eccentricity}),
      num("k_g", {p.k_g}),
      num("w_c", {p.w_c}),
      num("delta_eta", {p.delta_eta}),
      num("delta_h_m", {p.delta_h_m}),
      num("lobes", {static_cast<double>(p.lobes)}),
      num("quadrature_order", {static_cast<double>(p.quadrature_order)}),
      txt("r_fresnel", p.r_half_angle_fresnel ? "half_angle" : "per_h"),
      num("max_order", {static_cast<double>(p.max_order)}),
      txt("n_theta_d", p.specular_theta_d ? "specular" : "exit"),
  };
}

}  // namespace fiberlab::analytic
