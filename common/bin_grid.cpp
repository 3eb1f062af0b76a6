#include "common/bin_grid.h"

#include <algorithm>
#include <cmath>

#include "common/units.h"

namespace fiberlab {

BinGrid BinGrid::make(int n_theta, int n_phi, ThetaBinning binning) {
  BinGrid g;
  g.theta_binning = binning;
  g.theta_edges.resize(n_theta + 1);
  for (int i = 0; i <= n_theta; ++i) {
    const double t = -1.0 + 2.0 * i / n_theta;  // in [-1, 1]
    g.theta_edges[i] = binning == ThetaBinning::Uniform ? t * (kPi / 2) : std::asin(t);
  }
  g.theta_edges.front() = -kPi / 2;
  g.theta_edges.back() = kPi / 2;
  g.phi_edges.resize(n_phi + 1);
  for (int j = 0; j <= n_phi; ++j) g.phi_edges[j] = -kPi + kTwoPi * j / n_phi;
  return g;
}

int BinGrid::theta_bin(double theta) const {
  const int n = n_theta();
  const double x = theta_binning == ThetaBinning::Uniform ? (theta + kPi / 2) / kPi
                                                          : 0.5 * (std::sin(theta) + 1.0);
  int i = static_cast<int>(std::floor(x * n));
  i = std::clamp(i, 0, n - 1);
  // The closed-form index can be off by one at an edge: settle it on the edges.
  if (i > 0 && theta < theta_edges[i]) --i;
  else if (i < n - 1 && theta >= theta_edges[i + 1]) ++i;
  return i;
}

int BinGrid::phi_bin(double phi) const {
  const int n = n_phi();
  int j = static_cast<int>(std::floor((phi + kPi) / kTwoPi * n));
  j = std::clamp(j, 0, n - 1);
  if (j > 0 && phi < phi_edges[j]) --j;
  else if (j < n - 1 && phi >= phi_edges[j + 1]) ++j;
  return j;
}

double BinGrid::theta_band(int i) const {
  return std::sin(theta_edges[i + 1]) - std::sin(theta_edges[i]);
}

std::string to_string(ThetaBinning b) {
  return b == ThetaBinning::Uniform ? "uniform" : "equal_area";
}

}  // namespace fiberlab
