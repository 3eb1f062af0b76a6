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

// The values of the models' parameters. Each model reads the fields its
// parameter table names (model_params.h, model_registry.h): only those are
// settable with `--set KEY=VALUE` for that model, and only those are written
// to its predictions. The defaults here are neutral values for code that
// builds a model directly (tests); a model's defaults on the command line are
// its table's. Lists are indexed by lobe p, the last entry applying to every
// larger p. Angles in radians here (degrees on the command line).
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
  // d'Eon 2011 only: the R lobe's Fresnel term. true = Eq. 12 as published,
  // F(eta, arccos(wi.wr)/2) at the exit direction; false = Eq. 14 per h,
  // F(eta, arccos(cos theta_d cos gamma_i)) (`r_fresnel=half_angle|per_h`).
  bool r_half_angle_fresnel = true;
  // d'Eon 2011 only: highest order p traced explicitly in the last lobe; the
  // energy of the orders above goes to the uniform residual (`max_order=N`).
  int max_order = 40;
  // d'Eon 2011 only: theta_d at which N_p is evaluated. false (published):
  // theta_d = (theta_r - theta_i)/2 of the exit direction; true: theta_d =
  // -theta_i, the specular cone's, so that S = M_p(theta_r) N_p(phi) is a
  // product: exactly the simulator's `exit_blur` (SPEC s3)
  // (`n_theta_d=exit|specular`).
  bool specular_theta_d = false;
  // Chiang et al. 2016 only: roughness in [0, 1] (their beta_m -> v and
  // beta_n -> s mappings) and the cuticle scale tilt (radians, > 0 towards
  // the root as SPEC's scale_tilt; the model rotates by 2^k of it).
  double beta_m = 0.3, beta_n = 0.3;
  double scale_tilt = 0.0;
  int chiang_mp = 0;  // M_p: 0 d'Eon's exact, 1 pbrt-v4's numerics (`mp=exact|pbrt_v4`)
  // Huang et al. 2022 only (huang2022.h): GGX roughness alpha, per-lobe
  // factors (R, TT, TRT), masking (0 separable, 1 correlated, 2 none), the
  // flux onto the mesonormal (true) or the projected width, and the number
  // of points of its quadrature (also uses eccentricity and scale_tilt).
  double ggx_roughness = 0.3;
  std::vector<double> lobe_scale{1.0, 1.0, 1.0};
  int huang_masking = 0;
  int huang_residual = 0;  // p >= 3: 0 Cycles' sampler's residual, 1 its eval()'s
  bool mesonormal_flux = true;
  double quadrature_points = 4194304.0;
};

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
  // Number of tally lobes L the model predicts (ModelParams::lobes). The
  // default bin_probabilities() uses it; models built from ModelParams should
  // return params.lobes (the factory makes sure they do).
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
