#include "sim/microfacet_normal.h"

#include <algorithm>
#include <cmath>

namespace fiberlab::sim {

Vec3 smooth_normal(const Vec3& d, const BoundaryNormals& n) {
  return d.dot(n.facing) < 0.0 ? n.facing : n.untilted_facing;
}

namespace {

// m for a longitudinal offset dl and an azimuthal offset da (SPEC section 3):
// n_f = sin(theta_n) u + cos(theta_n) n_perp (n_perp = (pv, pw) in the normal
// plane) is tilted to inclination theta_n + dl in its plane with u, then
// turned by da about u. sin and cos of theta_n + dl by the angle-sum rule.
inline Vec3 rotated_normal(double sin_n, double cos_n, double pv, double pw, double dl,
                           double da) {
  const double sl = std::sin(dl), cl = std::cos(dl), ca = std::cos(da), sa = std::sin(da);
  const double st = sin_n * cl + cos_n * sl, ct = cos_n * cl - sin_n * sl;
  return Vec3(st, ct * (pv * ca - pw * sa), ct * (pv * sa + pw * ca));
}

// |x| for x ~ Normal(0, sigma^2) weighted by |x|: a Rayleigh deviate.
inline double rayleigh(double sigma, PhotonRandom& rng) {
  return sigma * std::sqrt(-2.0 * std::log(rng.uniform_open0()));
}

}  // namespace

// The target density of m is G(dl, da) max(0, -d.m), G the Gaussian of the
// offsets. Two exact rejection samplers for it:
//
// (a) propose from G, accept with probability max(0, -d.m) <= 1. Efficient
//     when n_f faces the photon squarely (-d.n_f near 1).
// (b) at grazing incidence (a) rejects almost everything (46 draws per
//     photon on the benchmark's case b), so propose instead from
//     G(dl, da) B(dl, da) with the envelope B = c + |dl| + |da|, c =
//     max(0, -d.n_f), and accept with probability max(0, -d.m) / B. B bounds
//     -d.m because -d.m = -d.n_f - d.(m - n_f) <= c + angle(m, n_f) and the
//     two rotations move n_f by at most |dl| + |da| (the turn about u moves a
//     vector by at most |da|). G B is a mixture of three easy densities: G
//     (weight c), G |dl| (weight E|dl| = sigma_l sqrt(2/pi): |dl| Rayleigh
//     with a random sign) and G |da| (likewise).
// (c) when n_f faces away from the photon by eps = asin(d.n_f) >= 0, both
//     reject almost everything once eps is several beta (the visible normals
//     are all in the tail): see far_tail_normal below.
// All three accept m with density proportional to G max(0, -d.m): the choice
// between them changes the number of draws, never the distribution.
//
// (c) in detail. Let x = (dl / beta_long, da / beta_azim) (standard normal
// in the plane), rho = |x| and b = max(beta_long, beta_azim). The angle
// delta between m and n_f is at most the length of the coordinate path
// sqrt(dl^2 + da^2) <= b rho (the metric of the sphere in (inclination,
// azimuth) is dt^2 + cos^2 t da^2). n_f is pi/2 + eps away from -d, so m is
// at least pi/2 + eps - delta away from it and
//   -d.m <= sin(delta - eps) <= b rho - eps,   and -d.m <= 0 when b rho <= eps.
// So propose x from the normal density times the envelope (b rho - eps)+,
// and accept with probability (-d.m)+ / (b rho - eps): exact, with no
// truncation of the tail. With rho0 = eps / b the envelope's radius has
// density ~ rho (rho - rho0) exp(-rho^2 / 2) on rho > rho0, its direction is
// uniform. Substituting y = rho - rho0 and w = rho0 y + y^2 / 2 (so dw =
// rho dy) gives density ~ y(w) exp(-w): propose w ~ Gamma(2, 1) (density
// w exp(-w)) and accept with probability rho0 y / w <= 1 (y <= w / rho0).
// Used from rho0 >= kFarTailSigmas, where that acceptance is >= ~0.6.
namespace {

std::optional<Vec3> far_tail_normal(const Vec3& d, double sin_n, double cos_n, double pv,
                                    double pw, double eps, double beta_long, double beta_azim,
                                    PhotonRandom& rng, int max_tries, long& tries) {
  const double b = std::max(beta_long, beta_azim);
  if (b <= 0.0) return std::nullopt;  // no roughness: no visible normal at all
  const double rho0 = eps / b;
  for (int k = 0; k < max_tries; ++k) {
    ++tries;
    const double w = -std::log(rng.uniform_open0() * rng.uniform_open0());  // Gamma(2, 1)
    const double y = 2.0 * w / (std::sqrt(rho0 * rho0 + 2.0 * w) + rho0);  // rho0 y + y^2/2 = w
    if (rng.uniform() * w >= rho0 * y) continue;
    const double psi = 6.283185307179586 * rng.uniform();
    const double rho = rho0 + y;
    const double dl = beta_long * rho * std::cos(psi), da = beta_azim * rho * std::sin(psi);
    const Vec3 m = rotated_normal(sin_n, cos_n, pv, pw, dl, da);
    const double visible = -d.dot(m);
    if (visible > 0.0 && rng.uniform() * (b * y) < visible) return m;  // b y = b rho - eps
  }
  return std::nullopt;
}

}  // namespace

double far_tail_threshold(double beta_max) {
  const double angle = kFarTailSigmas * beta_max;
  return angle < 1.5707963267948966 ? std::sin(angle) : 2.0;
}

std::optional<Vec3> gaussian_normal(const Vec3& d, const Vec3& n_facing, double beta_long,
                                    double beta_azim, PhotonRandom& rng, int max_tries,
                                    long& tries) {
  // n_f is never parallel to u: |tilt| < 45 deg.
  const double sin_n = n_facing.x();
  const double cos_n = std::sqrt(n_facing.y() * n_facing.y() + n_facing.z() * n_facing.z());
  const double inv = 1.0 / cos_n;
  const double pv = n_facing.y() * inv, pw = n_facing.z() * inv;
  const double d_dot_n = d.dot(n_facing);
  if (d_dot_n >= far_tail_threshold(std::max(beta_long, beta_azim)))
    return far_tail_normal(d, sin_n, cos_n, pv, pw, std::asin(std::min(1.0, d_dot_n)), beta_long,
                           beta_azim, rng, max_tries, tries);
  const double c = std::max(0.0, -d_dot_n);
  constexpr double kSqrt2OverPi = 0.7978845608028654;
  const double w_long = beta_long * kSqrt2OverPi, w_azim = beta_azim * kSqrt2OverPi;
  const bool use_envelope = c < 0.5;  // sampler (b) below -d.n_f = 0.5
  const double w_total = c + w_long + w_azim;
  if (use_envelope && w_total <= 0.0) return std::nullopt;  // no visible normal at all
  for (int k = 0; k < max_tries; ++k) {
    ++tries;
    double dl, da, bound = 1.0;
    if (!use_envelope) {
      dl = beta_long * rng.normal();
      da = beta_azim * rng.normal();
    } else {
      const double pick = w_total * rng.uniform();
      if (pick < c) {
        dl = beta_long * rng.normal();
        da = beta_azim * rng.normal();
      } else if (pick < c + w_long) {
        dl = rayleigh(beta_long, rng);  // magnitude first, then its sign
        if (rng.uniform() < 0.5) dl = -dl;
        da = beta_azim * rng.normal();
      } else {
        dl = beta_long * rng.normal();
        da = rayleigh(beta_azim, rng);
        if (rng.uniform() < 0.5) da = -da;
      }
      bound = c + std::abs(dl) + std::abs(da);
    }
    const Vec3 m = rotated_normal(sin_n, cos_n, pv, pw, dl, da);
    const double visible = -d.dot(m);
    if (visible > 0.0 && rng.uniform() * bound < visible) return m;
  }
  return std::nullopt;
}

}  // namespace fiberlab::sim
