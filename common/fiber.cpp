#include "common/fiber.h"

#include <cmath>

#include <fmt/format.h>

#include "common/physical_limits.h"
#include "common/units.h"

namespace fiberlab {
namespace {

using config::Reader;
using config::Rule;

constexpr int kMaxChannels = 64;

// The bounds and why: common/physical_limits.h.
const Rule kEta{"must be in (1, 1e9]: beyond 1e9 the Fresnel transmittance is lost in rounding",
                [](double x) { return x > 1.0 && x <= kMaxEta; }};
const Rule kEccentricity{"must be in [2.2250738585072014e-308, 1]: a smaller ratio is a subnormal "
                         "double (fewer bits; its inverse overflows below 5.6e-309)",
                         [](double x) { return x >= kMinEccentricity && x <= 1.0; }};
const Rule kTilt{"must be in (-45, 45) degrees", [](double x) { return std::fabs(x) < 45.0; }};
const Rule kNonNegative{"must be a finite number >= 0", [](double x) { return x >= 0.0; }};
const Rule kSigmaA{"must be a finite number >= 0, or a list of 1 to 64 such numbers",
                   [](double x) { return x >= 0.0; }};
const Rule kMedullaRadius{"must be in (0, 1): a fraction of the fiber's semi-axes",
                          [](double x) { return x > 0.0 && x < 1.0; }};
const Rule kAnisotropy{"must be in (-1, 1)", [](double x) { return x > -1.0 && x < 1.0; }};
const Rule kMedullaEta{"must be in [1, 1e9]", [](double x) { return x >= 1.0 && x <= kMaxEta; }};

// fiber.sigma_a or fiber.melanin (one of them; neither: the default sigma_a).
void read_absorption(const Reader& r, const YAML::Node& n, Fiber& f) {
  if (n["sigma_a"] && n["melanin"])
    r.fail("fiber.sigma_a and fiber.melanin are both given (must give one or the other)");
  if (n["sigma_a"]) {
    const YAML::Node s = n["sigma_a"];
    f.sigma_a = r.numbers(s, "fiber.sigma_a", kSigmaA, true);
    if (f.sigma_a.size() > static_cast<std::size_t>(kMaxChannels))
      r.bad("fiber.sigma_a", s, fmt::format("has {} channels", f.sigma_a.size()),
            fmt::format("must have 1 to {} channels", kMaxChannels));
  }
  if (n["melanin"]) {
    const YAML::Node m = r.section(n["melanin"], "fiber.melanin", {"eumelanin", "pheomelanin"});
    if (m.size() == 0)
      r.bad("fiber.melanin", n["melanin"], "is empty", "must give eumelanin and/or pheomelanin");
    const double ce = m["eumelanin"] ? r.number(m["eumelanin"], "fiber.melanin.eumelanin",
                                                kNonNegative) : 0.0;
    const double cp = m["pheomelanin"] ? r.number(m["pheomelanin"], "fiber.melanin.pheomelanin",
                                                  kNonNegative) : 0.0;
    f.eumelanin = ce;
    f.pheomelanin = cp;
    f.sigma_a = sigma_a_from_melanin(ce, cp);
  }
}

// fiber.medulla (docs/FUR.md), after the fiber's own keys: its sigma_a has
// the fiber's channels, and its eta defaults to the fiber's.
void read_medulla(const Reader& r, const YAML::Node& parent, Fiber& f) {
  const YAML::Node n = parent["medulla"];
  if (!n) return;
  const std::string path = "fiber.medulla";
  const YAML::Node m = r.section(n, path, {"radius", "sigma_s", "sigma_a", "g", "eta"});
  for (const char* key : {"radius", "sigma_s"})
    if (!m[key])
      r.fail(fmt::format("{}.{} is missing (a medulla needs radius in (0, 1) and sigma_s >= 0)",
                         path, key));
  Medulla md;
  md.radius = r.number(m["radius"], path + ".radius", kMedullaRadius);
  md.sigma_s = r.number(m["sigma_s"], path + ".sigma_s", kNonNegative);
  md.sigma_a.assign(f.sigma_a.size(), 0.0);
  if (m["sigma_a"]) {
    const Rule rule{fmt::format("must be a finite number >= 0, or a list of {} such numbers (the "
                                "fiber's channels)", f.sigma_a.size()),
                    kSigmaA.ok};
    md.sigma_a = r.numbers(m["sigma_a"], path + ".sigma_a", rule, true);
    if (md.sigma_a.size() == 1) md.sigma_a.assign(f.sigma_a.size(), md.sigma_a.front());
    if (md.sigma_a.size() != f.sigma_a.size())
      r.bad(path + ".sigma_a", m["sigma_a"], fmt::format("has {} channels", md.sigma_a.size()),
            fmt::format("must have the fiber's {} channels, or be one number", f.sigma_a.size()));
  }
  if (m["g"]) md.g = r.number(m["g"], path + ".g", kAnisotropy);
  md.eta = m["eta"] ? r.number(m["eta"], path + ".eta", kMedullaEta) : f.eta;
  f.medulla = md;
}

// The fiber block's medulla line (empty without one).
std::string medulla_yaml(const std::optional<Medulla>& m) {
  using config::number_text;
  if (!m) return "";
  return fmt::format("  medulla: {{radius: {}, sigma_s: {}, sigma_a: {}, g: {}, eta: {}}}\n",
                     number_text(m->radius), number_text(m->sigma_s),
                     config::list_text(m->sigma_a, number_text), number_text(m->g), number_text(m->eta));
}

}  // namespace

Fiber read_fiber(const Reader& r, const YAML::Node& config) {
  Fiber f;
  const YAML::Node n = r.section(config["fiber"], "fiber",
                                 {"eta", "eccentricity", "scale_tilt", "sigma_a", "melanin", "medulla"});
  if (n["eta"]) f.eta = r.number(n["eta"], "fiber.eta", kEta);
  if (n["eccentricity"]) f.eccentricity = r.number(n["eccentricity"], "fiber.eccentricity", kEccentricity);
  if (n["scale_tilt"]) f.scale_tilt = deg_to_rad(r.number(n["scale_tilt"], "fiber.scale_tilt", kTilt));
  read_absorption(r, n, f);
  read_medulla(r, n, f);
  f.roughness = roughness::read(r, config);
  // Masking's removed weight is absorbed along the cortex path only
  // (sim/life/exit_scoring.cpp), so the two are not combined.
  if (f.medulla && roughness::masking(f.roughness) != Masking::None)
    r.fail("fiber.medulla is not allowed with roughness.masking = smith_g1 (allowed with "
           "masking: none)");
  return f;
}

std::string fiber_yaml(const Fiber& f) {
  using config::list_text;
  using config::number_text;
  const bool melanin = f.eumelanin && f.pheomelanin &&
                       f.sigma_a == sigma_a_from_melanin(*f.eumelanin, *f.pheomelanin);
  const std::string absorption =
      melanin ? fmt::format("melanin: {{eumelanin: {}, pheomelanin: {}}}  # sigma_a = {}",
                            number_text(*f.eumelanin), number_text(*f.pheomelanin),
                            list_text(f.sigma_a, number_text))
              : "sigma_a: " + list_text(f.sigma_a, number_text);
  return fmt::format(
      "fiber:\n"
      "  eta: {}\n"
      "  eccentricity: {}\n"
      "  scale_tilt: {}\n"
      "  {}\n"
      "{}"
      "{}",
      number_text(f.eta), number_text(f.eccentricity), config::degrees_text(f.scale_tilt), absorption,
      medulla_yaml(f.medulla), roughness::yaml(f.roughness));
}

void write_fiber(h5::File& file, const Fiber& f) {
  file.create_group("/fiber");
  file.set_attr("/fiber", "eta", f.eta);
  file.set_attr("/fiber", "eccentricity", f.eccentricity);
  file.set_attr("/fiber", "scale_tilt", f.scale_tilt);
  file.set_attr("/fiber", "sigma_a", f.sigma_a);
  if (const auto& m = f.medulla) {  // docs/FUR.md
    file.create_group("/fiber/medulla");
    file.set_attr("/fiber/medulla", "radius", m->radius);
    file.set_attr("/fiber/medulla", "sigma_s", m->sigma_s);
    file.set_attr("/fiber/medulla", "sigma_a", m->sigma_a);
    file.set_attr("/fiber/medulla", "g", m->g);
    file.set_attr("/fiber/medulla", "eta", m->eta);
  }
  file.create_group("/roughness");
  file.set_attr("/roughness", "model", roughness::name(f.roughness));
  for (const roughness::Attribute& a : roughness::attributes(f.roughness))
    std::visit([&](const auto& value) { file.set_attr("/roughness", a.name, value); }, a.value);
}

std::vector<double> sigma_a_from_melanin(double eumelanin, double pheomelanin) {
  // d'Eon et al. 2011, section 6.1: absorption per unit radius of each pigment.
  constexpr double eu[3] = {0.419, 0.697, 1.37};
  constexpr double pheo[3] = {0.187, 0.4, 1.05};
  std::vector<double> sigma_a(3);
  for (int c = 0; c < 3; ++c) sigma_a[c] = eumelanin * eu[c] + pheomelanin * pheo[c];
  return sigma_a;
}

}  // namespace fiberlab
