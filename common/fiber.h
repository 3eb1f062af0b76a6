#pragma once
// The fiber: what the simulator traces and what the analytic models are
// given (SPEC sections 2-4), described once. All angles are in radians; the
// YAML config has degrees.
#include <optional>
#include <string>
#include <vector>

#include "common/config_reader.h"
#include "common/h5_file.h"
#include "common/roughness/roughness.h"

namespace fiberlab {

// `fiber.medulla` (docs/FUR.md): a scattering core, the cross-section scaled
// by `radius` about the fiber's axis, filled with a medium of scattering
// coefficient sigma_s and absorption sigma_a (1/R, as the fiber's), a
// Henyey-Greenstein phase function of anisotropy g, and index eta (the
// fiber's when not given: then its boundary is no interface).
struct Medulla {
  double radius = 0.5;          // k in (0, 1), of the fiber's semi-axes
  double sigma_s = 0.0;         // 1/R, finite, >= 0
  std::vector<double> sigma_a;  // 1/R per channel (the fiber's channels)
  double g = 0.0;               // in (-1, 1)
  double eta = 1.55;            // relative to the outer medium, >= 1

  friend bool operator==(const Medulla&, const Medulla&) = default;
};

struct Fiber {
  double eta = 1.55;           // relative index, > 1
  double eccentricity = 1.0;   // minor/major, (0, 1]
  double scale_tilt = 0.0;     // alpha, radians, towards the root
  std::vector<double> sigma_a{0.0, 0.0, 0.0};  // 1/R per channel
  // Set when the config gave melanin instead of sigma_a (sigma_a is then derived).
  std::optional<double> eumelanin, pheomelanin;
  std::optional<Medulla> medulla;  // none: a plain fiber
  Roughness roughness = roughness::Gaussian{};

  friend bool operator==(const Fiber&, const Fiber&) = default;
};

// The `fiber:` and `roughness:` sections of a run config, checked (every
// error one line naming the field and what is allowed).
Fiber read_fiber(const config::Reader& r, const YAML::Node& config);

// The `fiber:` and `roughness:` blocks of a resolved config (degrees, every
// key explicit; read back by read_fiber to an equal Fiber).
std::string fiber_yaml(const Fiber& f);

// The /fiber and /roughness groups of a result file (docs/FILE_FORMAT.md).
void write_fiber(h5::File& file, const Fiber& f);

// Derived sigma_a from melanin concentrations, d'Eon 2011 section 6.1.
std::vector<double> sigma_a_from_melanin(double eumelanin, double pheomelanin);

}  // namespace fiberlab
