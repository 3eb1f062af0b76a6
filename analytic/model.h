#pragma once
// The common face of every analytic fiber-scattering model: a probability
// density of the exit direction per d(theta_r) d(phi) (SPEC section 7), per
// lobe p and colour channel, and its integral over the bins of a BinGrid.
//
// Conventions (SPEC section 7): d'Eon-style models p = S cos(theta_r);
// Marschner 2003 p = S cos^2(theta_r). phi is the relative azimuth
// phi_r - phi_i in [-pi, pi). Angles in radians.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/bin_grid.h"

namespace fiberlab::analytic {

enum class Absorption { Published, Chord };

// Every model parameter, settable by name with `--set KEY=VALUE`. Lists are
// indexed by lobe p, the last entry applying to every larger p. Angles in
// radians here (degrees on the command line).
struct ModelParams {
  double eta = 1.55;
  std::vector<double> sigma_a{0.0, 0.0, 0.0};  // 1/R per channel
  std::vector<double> beta_long{0.0};          // per p
  std::vector<double> beta_azim{0.0};          // per p
  std::vector<double> alpha{0.0};              // shift of theta_r per p
  Absorption absorption = Absorption::Published;
  int lobes = 4;  // lobes 0..L-2 separately, lobe L-1 = every p >= L-1
  // Marschner 2003 only.
  bool two_theta_h = false;       // longitudinal=theta_h|two_theta_h
  bool exact_roots = false;       // roots=cubic|exact
  double eccentricity = 1.0;      // a = minor/major
  double k_g = 0.5, w_c = 0.0, delta_eta = 0.0, delta_h_m = 0.0;  // caustics, see marschner2003.h
  // d'Eon 2011 only: Gauss-Legendre order of the N_p integral over h.
  int quadrature_order = 35;
};

class Model {
 public:
  virtual ~Model() = default;
  virtual std::string name() const = 0;

  // Density of lobe `lobe` (the tally's lobe index: the last lobe sums every
  // p >= lobes-1) per d(theta_r) d(phi), one value per channel in `out`.
  virtual void density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
                       std::vector<double>& out) const = 0;

  // Probability of each bin: out[((lobe * n_theta + i) * n_phi + j) * C + c].
  // The default integrates density() by quadrature; models with singular
  // densities (the smooth cylinder's delta in theta_r) override it.
  virtual std::vector<double> bin_probabilities(const BinGrid& grid, double theta_i,
                                                double phi_i) const;
};

}  // namespace fiberlab::analytic
