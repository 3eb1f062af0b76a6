#include "common/roughness/gaussian.h"

#include <fmt/format.h>

#include "common/units.h"

namespace fiberlab::roughness {

std::string Gaussian::text() const {
  return fmt::format("gaussian beta = [{:g}, {:g}] deg", rad_to_deg(beta_long), rad_to_deg(beta_azim));
}

}  // namespace fiberlab::roughness
