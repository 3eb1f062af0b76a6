#pragma once
// Roughness model `exit_blur` (SPEC section 3): smooth interfaces, and the
// exit direction of a photon that leaves after p internal paths blurred
// once, with widths beta_long[p] and beta_azim[p] (the last entry of a list
// for every larger p).
#include <algorithm>
#include <string>
#include <vector>

#include "common/roughness/beta_widths.h"

namespace fiberlab::roughness {

struct ExitBlur : BetaLists {
  static constexpr const char* kName = "exit_blur";
  static const std::vector<std::string>& keys() { return kBetaKeys; }

  static ExitBlur read(const config::Reader& r, const YAML::Node& n) { return {read_betas(r, n, kName, true)}; }
  std::string yaml() const { return betas_yaml(*this); }
  std::vector<Attribute> attributes() const { return betas_attributes(*this); }
  std::string describe() const { return describe_betas(*this); }
  std::string text() const { return kName; }

  // The entry for lobe p of a list indexed by p (the last for larger p).
  static double for_lobe(const std::vector<double>& list, int p) {
    return list[std::min<std::size_t>(static_cast<std::size_t>(p), list.size() - 1)];
  }

  friend bool operator==(const ExitBlur&, const ExitBlur&) = default;
};

}  // namespace fiberlab::roughness
