#pragma once
// Roughness model `gaussian` (SPEC section 3): at every interface event the
// facet normal is the surface normal tilted by Gaussian angles of standard
// deviation beta_long along the fiber axis and beta_azim about it.
#include <string>
#include <vector>

#include "common/roughness/beta_widths.h"

namespace fiberlab::roughness {

struct Gaussian {
  static constexpr const char* kName = "gaussian";
  static const std::vector<std::string>& keys() { return kBetaKeys; }

  double beta_long = 0.0, beta_azim = 0.0;  // radians, in [0, pi/2]

  static Gaussian read(const config::Reader& r, const YAML::Node& n) {
    const BetaLists b = read_betas(r, n, kName, false);
    return {b.beta_long.front(), b.beta_azim.front()};
  }
  std::string yaml() const { return betas_yaml(lists()); }
  std::vector<Attribute> attributes() const { return betas_attributes(lists()); }
  std::string describe() const { return describe_betas(lists()); }
  std::string text() const;

  friend bool operator==(const Gaussian&, const Gaussian&) = default;

 private:
  BetaLists lists() const { return {{beta_long}, {beta_azim}}; }
};

}  // namespace fiberlab::roughness
