#pragma once
// The tilt widths beta_long and beta_azim (SPEC section 3) of the models that
// take them (smooth, gaussian, exit_blur): reading, YAML text, file
// attributes and description, shared by those models' files.
#include <string>
#include <vector>

#include "common/config_reader.h"
#include "common/roughness/attribute.h"

namespace fiberlab::roughness {

struct BetaLists {
  std::vector<double> beta_long{0.0}, beta_azim{0.0};  // radians

  friend bool operator==(const BetaLists&, const BetaLists&) = default;
};

// The keys of the roughness section these models read.
inline const std::vector<std::string> kBetaKeys{"beta_long", "beta_azim"};

// beta_long and beta_azim of the `roughness` section `n` of model `model`
// (degrees in the file, radians here); beta_azim defaults to beta_long.
// `lists`: a list indexed by p is allowed (exit_blur; smooth keeps it
// unused), else one number each. Refuses the microfacet models' keys.
BetaLists read_betas(const config::Reader& r, const YAML::Node& n, const std::string& model, bool lists);

// "  beta_long: X\n  beta_azim: Y\n" (degrees; a number when one entry).
std::string betas_yaml(const BetaLists& b);
std::vector<Attribute> betas_attributes(const BetaLists& b);
// "beta_long [5] deg, beta_azim [10] deg" (`fiberlab info`).
std::string describe_betas(const BetaLists& b);

}  // namespace fiberlab::roughness
