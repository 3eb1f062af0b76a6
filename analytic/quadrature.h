#pragma once
// Quadrature rules shared by the analytic models: Gauss-Legendre nodes and
// weights on [-1, 1] (computed once per order by Newton's method on P_n, exact
// to rounding) and the wrapped-Gaussian bin integral of d'Eon 2011 Eq. 11.
#include <vector>

namespace fiberlab::analytic {

struct GaussLegendre {
  std::vector<double> x, w;  // nodes ascending on [-1, 1], weights summing to 2
};

// The n-point rule (n >= 1). Thread-safe; rules are cached.
const GaussLegendre& gauss_legendre(int n);

// Integral over [a, b] of a unit-integral Gaussian of standard deviation
// beta centred on mu: (erf((b-mu)/(sqrt2 beta)) - erf((a-mu)/(sqrt2 beta)))/2,
// computed with erfc in the tails so that tiny masses keep their relative accuracy.
double gaussian_interval_mass(double a, double b, double mu, double beta);

}  // namespace fiberlab::analytic
