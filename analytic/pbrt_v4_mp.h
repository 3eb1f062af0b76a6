#pragma once
// The longitudinal function M_p of pbrt-v4's HairBxDF as pbrt-v4 ships it
// (src/pbrt/bxdfs.h HairBxDF::Mp, src/pbrt/util/math.h I0 and LogI0), for
// `chiang2016 mp=pbrt_v4`: the renderer's numbers beside the function the
// paper defines (d'Eon 2011 Eq. 7, analytic/deon2011.h log_M_p). With
// a = cos(theta_i) cos(theta_r) / v and b = sin(theta_i) sin(theta_r) / v:
// - I0(x): the first 10 terms of the series sum_i (x^2/4)^i / (i!)^2
//   (below the true I0 by 3e-7 at x = 5, 0.32% at x = 10, 1.9% just below
//   x = 12: exact rational sums against the true I0).
// - log I0(x): for x > 12, x + (-log(2 pi) + log(1/x) + 1/(8x)) / 2, i.e.
//   the asymptotic series' correction log(1 + 1/(8x) + ...) ~ 1/(8x) taken
//   as 1/(16x); for x <= 12, log of the 10-term I0.
// - v <= 0.1: M_p = exp(log I0(a) - b - 1/v + 0.6931 + log(1/(2v)))
//   (csch(1/v) taken as 2 exp(-1/v), ln 2 as 0.6931);
//   v > 0.1: M_p = exp(-b) I0(a) / (2 v sinh(1/v)).
// pbrt evaluates these in single precision with a fast exp; here they are
// evaluated in double: the variant reproduces pbrt's formulas, not its
// rounding.
namespace fiberlab::analytic::pbrt_v4 {

double I0(double x);
double log_I0(double x);
// log M_p(v, theta_i, theta_r) by the formulas above (v > 0).
double log_M_p(double v, double theta_i, double theta_r);

}  // namespace fiberlab::analytic::pbrt_v4
