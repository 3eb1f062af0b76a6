#pragma once
// Where the fiber's physics stops being computed meaningfully in double
// precision: the bounds of fiber.eta and fiber.eccentricity, shared by the
// simulator's config (sim/run/settings.cpp) and the analytic models' parameter
// tables (analytic/model_params.cpp), so both refuse the same values.
#include <cfloat>

namespace fiberlab {

// Largest relative index: eta <= 1e9.
// A photon is transmitted with probability T = 1 - F (common/fresnel.h). For
// large eta, T ~ 4 cos_i / eta (4 / eta at normal incidence), while F is
// computed as a ratio of terms of order eta^4 with an absolute rounding error
// of a few 2^-53, and the uniform it is compared with has a step of 2^-52
// (sim/life/random.h): T's relative error grows as ~1.2e-16 eta (measured against
// long double over cos_i in [1e-3, 1]: 1.2e-7 at eta = 1e9, 1.3e-6 at 1e10,
// 0.12 at 1e15; tests/analytic/test_physical_limits.cpp). 1e9 keeps T's
// error below 1e-6, under the statistical error of any feasible run (1e12
// photons). Beyond about 1.16e77 = DBL_MAX^(1/4) F is inf / inf = NaN.
inline constexpr double kMaxEta = 1e9;

// Smallest minor/major axis ratio: eccentricity >= DBL_MIN = 2^-1022.
// The cross-section's geometry (sim/life/ellipse_cross_section.h) uses e, 1/e,
// sqrt(e) and 1/sqrt(e) times numbers of order 1: every product stays finite
// and at full precision while e and 1/e are normal doubles (measured against
// long double down to DBL_MIN: normals within 1e-8 rad, chord lengths within
// 1e-8 relative; tests/sim/test_physical_limits.cpp). Below DBL_MIN, e is a
// subnormal double, with fewer significant bits than the ratio written
// (so the fiber simulated is not the one asked for), and below 1/DBL_MAX
// (about 5.6e-309) 1/e overflows to inf, whence NaN positions and every
// photon truncated.
inline constexpr double kMinEccentricity = DBL_MIN;

}  // namespace fiberlab
