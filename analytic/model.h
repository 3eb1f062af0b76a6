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

// Value of a per-lobe list for lobe p: the last entry applies to every larger p.
inline double for_lobe(const std::vector<double>& list, int p) {
  if (list.empty()) return 0.0;
  return list[static_cast<std::size_t>(p) < list.size() ? static_cast<std::size_t>(p)
                                                        : list.size() - 1];
}
// The tally's lobe index of path order p (SPEC section 6).
inline int lobe_of(int p, int lobes) { return p < lobes - 1 ? p : lobes - 1; }

class Model {
 public:
  virtual ~Model() = default;
  virtual std::string name() const = 0;
  // Number of tally lobes L the model predicts (its parameter `lobes`). The
  // default bin_probabilities() uses it.
  virtual int lobes() const { return 4; }

  // Density of lobe `lobe` (the tally's lobe index: the last lobe sums every
  // p >= lobes-1) per d(theta_r) d(phi), one value per channel in `out`.
  virtual void density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
                       std::vector<double>& out) const = 0;

  // Probability of each bin: out[((lobe * n_theta + i) * n_phi + j) * C + c].
  // The default integrates density() by a 6 x 6-point Gauss-Legendre rule
  // per bin (fine for densities smooth on the bin scale); models with
  // singular or sharply peaked densities override it.
  virtual std::vector<double> bin_probabilities(const BinGrid& grid, double theta_i,
                                                double phi_i) const;
};

}  // namespace fiberlab::analytic
