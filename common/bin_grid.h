#pragma once
// The (theta_r, phi) histogram grid of SPEC section 6, shared by the tally,
// the analytic bin probabilities and the comparison.
#include <cstddef>
#include <string>
#include <vector>

namespace fiberlab {

enum class ThetaBinning { Uniform, EqualArea };

struct BinGrid {
  ThetaBinning theta_binning = ThetaBinning::Uniform;
  std::vector<double> theta_edges;  // n_theta + 1, radians, [-pi/2, pi/2]
  std::vector<double> phi_edges;    // n_phi + 1, radians, [-pi, pi)

  // theta bins uniform in theta or in sin(theta); phi bins uniform on [-pi, pi).
  static BinGrid make(int n_theta, int n_phi, ThetaBinning binning);

  int n_theta() const { return static_cast<int>(theta_edges.size()) - 1; }
  int n_phi() const { return static_cast<int>(phi_edges.size()) - 1; }

  // Bin index of an inclination in [-pi/2, pi/2] and a relative azimuth in
  // [-pi, pi). Values on the closed upper edge go to the last bin.
  int theta_bin(double theta) const;
  int phi_bin(double phi) const;

  // Omega_b = (sin theta_hi - sin theta_lo)(phi_hi - phi_lo), SPEC section 6:
  // the product of the theta band's and the phi bin's factors (a whole grid's
  // solid angles take one band per row, not two sines per bin).
  double solid_angle(int i_theta, int i_phi) const { return theta_band(i_theta) * phi_width(i_phi); }
  double theta_band(int i_theta) const;  // sin theta_hi - sin theta_lo
  double phi_width(int i_phi) const { return phi_edges[i_phi + 1] - phi_edges[i_phi]; }
};

std::string to_string(ThetaBinning b);

}  // namespace fiberlab
