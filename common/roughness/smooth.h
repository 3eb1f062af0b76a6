#pragma once
// Roughness model `smooth` (SPEC section 3): every facet normal is the
// (tilted) surface normal. It takes the beta keys as the other non-microfacet
// models do and keeps them as given, unused (the config and the result file
// show them).
#include <string>
#include <vector>

#include "common/roughness/beta_widths.h"

namespace fiberlab::roughness {

struct Smooth : BetaLists {
  static constexpr const char* kName = "smooth";
  static const std::vector<std::string>& keys() { return kBetaKeys; }

  static Smooth read(const config::Reader& r, const YAML::Node& n) { return {read_betas(r, n, kName, true)}; }
  std::string yaml() const { return betas_yaml(*this); }
  std::vector<Attribute> attributes() const { return betas_attributes(*this); }
  std::string describe() const { return describe_betas(*this); }
  std::string text() const { return kName; }

  friend bool operator==(const Smooth&, const Smooth&) = default;
};

}  // namespace fiberlab::roughness
