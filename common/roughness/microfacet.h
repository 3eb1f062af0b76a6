#pragma once
// Roughness models `beckmann` and `ggx` (SPEC section 3): microfacet
// distributions of normals about the tilted normal with roughness alpha along
// the fiber axis (longitudinal) and about it (azimuthal), sampled as visible
// normals (sim/roughness/microfacet_roughness.h), with optional Smith G1
// masking (common/roughness/masking.h).
#include <string>
#include <vector>

#include "common/config_reader.h"
#include "common/roughness/attribute.h"
#include "common/roughness/masking.h"

namespace fiberlab::roughness {

// The fields and config rules both microfacet models share.
struct MicrofacetAlpha {
  double alpha_long = 0.0, alpha_azim = 0.0;  // each in (0, 10]
  Masking masking = Masking::None;

  static const std::vector<std::string>& keys();
  // `model` names the model in messages.
  static MicrofacetAlpha read(const config::Reader& r, const YAML::Node& n, const std::string& model);
  std::string yaml() const;
  std::vector<Attribute> attributes() const;
  std::string describe() const;
  // "ggx alpha = [0.3, 0.1]"
  std::string text(const std::string& model) const;

  friend bool operator==(const MicrofacetAlpha&, const MicrofacetAlpha&) = default;
};

struct Beckmann : MicrofacetAlpha {
  static constexpr const char* kName = "beckmann";
  static Beckmann read(const config::Reader& r, const YAML::Node& n) { return {MicrofacetAlpha::read(r, n, kName)}; }
  std::string text() const { return MicrofacetAlpha::text(kName); }
  friend bool operator==(const Beckmann&, const Beckmann&) = default;
};

struct Ggx : MicrofacetAlpha {
  static constexpr const char* kName = "ggx";
  static Ggx read(const config::Reader& r, const YAML::Node& n) { return {MicrofacetAlpha::read(r, n, kName)}; }
  std::string text() const { return MicrofacetAlpha::text(kName); }
  friend bool operator==(const Ggx&, const Ggx&) = default;
};

}  // namespace fiberlab::roughness
