#pragma once
// What to run: the resolved simulation configuration (SPEC section 11).
// All angles here are in radians; the YAML file has degrees.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/bin_grid.h"
#include "common/fiber.h"

namespace fiberlab::sim {

enum class Polarization { Scalar, Stokes };
// How a photon's exits are scored (SPEC section 5; docs/PHYSICS.md
// "Estimator"). `analog`: at every event the photon reflects with
// probability F and refracts otherwise, and scores its whole weight where it
// finally leaves. `expected_value`: at an event where one branch leaves the
// fiber at once, that branch is scored with the weight times its probability
// and the photon goes on along the other with the weight times one minus it
// (Russian roulette after an event once the weight is low:
// life::kRouletteBelow, sim/life/photon_life.h).
enum class Estimator { Analog, ExpectedValue };

// Settings::exit_normals: at most this many normals per scored exit (the
// batched tracer hands over a vector's split exits within one block:
// sim/life/batch_tracer.cpp).
inline constexpr int kMaxExitNormals = 32;
inline constexpr std::size_t kMaxExitNormalsEntries = 16;  // entries, by lobe p

struct SourceSettings {
  std::vector<double> theta_i{0.0};  // radians, each in (-pi/2, pi/2)
  bool phi_i_uniform = false;        // a randomly rotated fiber
  std::vector<double> phi_i{0.0};    // radians (unused when uniform)
  // Impact parameters h stratified by photon index (sim/life/source.h), or each
  // photon's h independent (the default: stratification measured no gain,
  // README "Stratified impact parameters"). Either way every h is uniform in [-1, 1).
  bool h_stratified = false;

  friend bool operator==(const SourceSettings&, const SourceSettings&) = default;
};

struct TallySettings {
  int n_theta = 90;
  int n_phi = 180;
  ThetaBinning theta_bins = ThetaBinning::Uniform;
  int lobes = 4;

  friend bool operator==(const TallySettings&, const TallySettings&) = default;
};

struct Settings {
  std::uint64_t photons = 1000000;  // per incident configuration
  std::uint64_t seed = 1;
  std::string output = "out.h5";
  Fiber fiber;  // with its roughness (common/fiber.h)
  SourceSettings source;
  TallySettings tally;
  int max_segments = 1000;
  int max_events_per_point = 1000;  // consistency-rule bound (SPEC section 5)
  Polarization polarization = Polarization::Scalar;
  // analog: the one with more error per CPU second on bench/configs cases b
  // and c (bench/figure_of_merit.py; docs/PHYSICS.md "Estimator").
  Estimator estimator = Estimator::Analog;
  // Exit splitting under `expected_value` (docs/PHYSICS.md "Estimator"):
  // at an event whose leaving branch is scored, the number of microfacet
  // normals (the event's own and exit_normals - 1 more) over which the
  // scored weight is spread, by lobe p (the last entry for every larger p).
  // {1}: no splitting.
  std::vector<int> exit_normals{1};
  int exit_normals_for(int p) const {
    return exit_normals[std::min<std::size_t>(static_cast<std::size_t>(p), exit_normals.size() - 1)];
  }

  // The incident configurations: every theta_i combined with every phi_i
  // (theta-major order). phi_i is NaN when uniform.
  struct Incidence {
    double theta_i, phi_i;
  };
  std::vector<Incidence> incidences() const;

  // Lobes in the tally and in result files: tally.lobes by p, and with a
  // medulla one more, `scattered`, after them (docs/FUR.md).
  int tally_lobes() const { return tally.lobes + (fiber.medulla ? 1 : 0); }

  // Field-by-field equality (exact doubles): to_yaml -> parse_settings_yaml
  // gives back an equal Settings.
  friend bool operator==(const Settings&, const Settings&) = default;
};

// Parses a YAML config. `origin` names the source in error messages (a file
// path). Throws fiberlab::Error with one line naming the field, the value and
// the allowed range.
Settings parse_settings_yaml(const std::string& yaml_text, const std::string& origin);
Settings load_settings(const std::string& path);
// A result file's stored config_yaml: as parse_settings_yaml, except that a
// config without an `estimator` key was written before the key existed, by
// the analog estimator.
Settings parse_stored_settings_yaml(const std::string& yaml_text, const std::string& origin);

// A command-line integer (--photons, --seed, --threads) read by the config's
// rules: 100000 or an exactly integral 1e5; not -1, 1.5, nan or anything
// outside [lo, hi]. Throws fiberlab::Error: "command line: --photons = -1 is
// out of range (must be an integer >= 1)".
std::uint64_t parse_integer_flag(const std::string& flag, const std::string& text,
                                 std::uint64_t lo, std::uint64_t hi);

// The resolved configuration as YAML (degrees, every key explicit): stored in
// result files as `config_yaml` and parseable again by parse_settings_yaml.
std::string to_yaml(const Settings& s);

std::string to_string(Polarization p);
std::string to_string(Estimator e);

}  // namespace fiberlab::sim
