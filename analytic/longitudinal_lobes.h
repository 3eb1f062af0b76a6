#pragma once
// Longitudinal scattering functions M_p(theta_i, theta_r) of the analytic
// models, kept apart from the azimuthal functions (azimuthal_lobes.h) and
// from the bin integration (bin_integration.h), as pbrt-v4 keeps Mp apart
// from Ap and Np (src/pbrt/bxdfs.h, HairBxDF).
// - The von Mises-Fisher marginal of d'Eon et al. 2011 Eq. 7 (SPEC s3, s7):
//   deon2011, chiang2016 (mp=exact), huang2022's residual lobe.
// - The Gaussian of Marschner et al. 2003 s5.1: marschner2003.
// pbrt-v4's own numerics of Eq. 7 (chiang2016 mp=pbrt_v4) are pbrt_v4_mp.h.
namespace fiberlab::analytic::longitudinal {

// log I0(x), x >= 0: power series below 30, the asymptotic expansion
// e^x / sqrt(2 pi x) (1 + 1/(8x) + 9/(2 (8x)^2) + ...) above (Abramowitz &
// Stegun 9.7.1; relative error < 1e-15 of I0 everywhere; the asymptotic
// terms shrink until k ~ 2x).
double log_I0(double x);
// log csch(x) for x > 0: log 2 - x - log1p(-exp(-2x)).
double log_csch(double x);
// d'Eon 2011 Eq. 7 in log space (csch and I0 overflow for small v):
//   log M_p(v, theta_i, theta_r) = log csch(1/v) - log(2v)
//     - sin(theta_i) sin(theta_r)/v + log I0(cos(theta_i) cos(theta_r)/v).
// Per unit theta_r; integrates to 1 against cos(theta_r) over [-pi/2, pi/2].
double vmf_log_M_p(double v, double theta_i, double theta_r);
double vmf_M_p(double v, double theta_i, double theta_r);

// g(beta; x): unit-integral zero-mean Gaussian with standard deviation beta
// (Marschner 2003 s5.1).
double gaussian(double beta, double x);
// Marschner 2003 s5.1: M_p = g(beta; theta_h - alpha_theta_r / 2) as
// published (Marschner's alpha_p shifts theta_h, half of the theta_r shift,
// SPEC s7; it integrates to 2 over theta_r for small beta, d'Eon 2011 s4.1),
// or with two_theta_h g(beta; 2 theta_h - alpha_theta_r) (Zinke & Weber;
// integrates to 1). theta_h = (theta_i + theta_r) / 2.
double gaussian_M_p(double beta, double alpha_theta_r, double theta_i, double theta_r, bool two_theta_h);

}  // namespace fiberlab::analytic::longitudinal
