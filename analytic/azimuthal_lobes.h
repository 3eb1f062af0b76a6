#pragma once
// Azimuthal detector functions D(phi) of the rough analytic models, with
// their cumulative distributions, kept apart from the longitudinal functions
// (longitudinal_lobes.h), from the path weights A(p, h) and Phi(p, h)
// (cylinder_paths.h) and from the bin integration (bin_integration.h), as
// pbrt-v4 keeps Np apart from Mp and Ap (src/pbrt/bxdfs.h, HairBxDF).
// A model's N_p(phi) = 1/2 int A(p, h) D(phi - Phi(p, h)) dh.
// - The wrapped Gaussian of d'Eon et al. 2011 Eq. 11 (deon2011).
// - The R lobe's shape under d'Eon 2011 Eq. 12 (deon2011, r_fresnel=half_angle).
// - The trimmed logistic of Chiang et al. 2016 (chiang2016; pbrt-v4's
//   TrimmedLogistic).
#include <cmath>

namespace fiberlab::analytic::azimuthal {

// d'Eon 2011 Eq. 11: D(beta; phi) = sum_k g(beta; phi - 2 pi k), unit
// integral over one period; the images beyond 8.5 beta are left out.
double wrapped_gaussian(double beta, double phi);
// The cumulative of the (unwrapped) Gaussian of standard deviation beta at
// offset x from its centre, 0.5 erfc(-x / (sqrt 2 beta)). A deposit over
// bins adds up the images (bin_integration.h, deposit_wrapped).
class GaussianCdf {
 public:
  explicit GaussianCdf(double beta) : s_(1.0 / (std::sqrt(2.0) * beta)) {}
  double operator()(double x) const { return 0.5 * std::erfc(-x * s_); }

 private:
  double s_;
};
// Half-width of the window outside which the Gaussian's mass is below
// erfc(8.5 / sqrt 2) / 2 ~ 1e-17: in standard deviations.
constexpr double kGaussianWindow = 8.5;

// G_0(phi) = (1/2) int D(beta; phi - Phi(0, h)) dh = (D * |cos(psi/2)| / 4)(phi):
// the R lobe's azimuthal shape before Eq. 12's direction-dependent Fresnel
// (Phi(0, h) = -2 asin h, dh = |cos(psi/2)| dpsi / 2).
// By its Fourier series: |cos(psi/2)| = 2/pi + sum_{k>=1} (-1)^(k+1)
// 4 / (pi (4k^2 - 1)) cos(k psi), and the detector multiplies coefficient k by
// g_k = exp(-k^2 beta^2 / 2), so
//   G_0(phi) = 1/4 [2/pi + sum_k (-1)^(k+1) 4 g_k / (pi (4k^2 - 1)) cos(k phi)],
// summed to K = ceil(8.9 / beta) with g_K < 1e-17 (the terms beyond add up to
// < 1e-20); cos(k phi) by the Chebyshev recurrence (rounding ~K^2 1e-16 on
// terms that shrink as g_k / k^2). For beta >= kHalfAngleSeriesBeta.
constexpr double kHalfAngleSeriesBeta = 0.005;
double half_angle_r_shape_series(double phi, double beta);
// The same by composite Gauss-Legendre over psi (panels below
// min(beta / 2, 0.2) / refine, 8 points), split at the kinks of |cos(psi/2)|:
// for narrower detectors, where the series is long.
double half_angle_r_shape_quadrature(double phi, double beta, double refine);

// Chiang 2016: the logistic distribution of scale s trimmed to [-pi, pi]
// and renormalised (pbrt-v4 TrimmedLogistic): density at x in [-pi, pi]
// (unit integral over [-pi, pi]) for s > 0.
double trimmed_logistic(double x, double s);
// Its cumulative from -pi, extended periodically: G(x + 2 pi k) = G(x) + k,
// so that the mass of the wrapped density on [a, b] is G(b) - G(a) for any
// a <= b (closed form: logistic CDF 1 / (1 + exp(-x / s))).
double trimmed_logistic_cumulative(double x, double s);
// Half-width of the window outside which the logistic's density is below
// e^-40 of its peak: in units of s.
constexpr double kLogisticWindow = 40.0;

}  // namespace fiberlab::analytic::azimuthal
