#pragma once
// Quadrature rules shared by the analytic models: Gauss-Legendre nodes and
// weights on [-1, 1] (computed once per order by Newton's method on P_n, exact
// to rounding) and the wrapped-Gaussian bin integral of d'Eon 2011 Eq. 11.
#include <cstddef>
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
// The same for n consecutive intervals [edges[j], edges[j + 1]], added to
// out[j * stride] (j < n): each value equal to gaussian_interval_mass's, with
// one erfc per edge instead of two per interval.
void add_gaussian_interval_masses(const double* edges, int n, double mu, double beta, double* out,
                                  std::size_t stride = 1);

}  // namespace fiberlab::analytic

namespace fiberlab::analytic {

// Piecewise polynomial interpolation in one variable on [lo, hi] (used to
// interpolate a model's phi-bin integrals in theta_r between a few exact
// evaluations): n_panels equal panels, each with the m >= 2
// Chebyshev-Lobatto points x_k = mid - half cos(pi k / (m - 1)), k = 0..m-1;
// neighbouring panels share their end point, so there are
// n_panels (m - 1) + 1 distinct nodes, numbered from lo. The Lagrange basis
// is evaluated by the barycentric formula (Berrut & Trefethen 2004, SIAM
// Review 46(3), Eq. 4.2 with the weights of Eq. 5.4), stable for any m.
class ChebyshevPanels {
 public:
  ChebyshevPanels(double lo, double hi, int n_panels, int m);
  int nodes() const { return n_panels_ * (m_ - 1) + 1; }
  int per_panel() const { return m_; }
  double node(int g) const;
  // The m basis values at x (clamped into [lo, hi]) into l[0..m), for the
  // nodes first, first + 1, ..., first + m - 1; returns first.
  int basis(double x, double* l) const;

 private:
  double lo_, width_;
  int n_panels_, m_;
  std::vector<double> unit_;  // Lobatto points on [0, 1]
};

}  // namespace fiberlab::analytic
