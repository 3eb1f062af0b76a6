#pragma once
// d'Eon, Francois, Hill, Letteri, Aubry 2011, "An Energy-Conserving Hair
// Reflectance Model" (papers/deon2011_energy_conserving_hair.txt), complete:
//
//   S(theta_i, theta_r, phi) = sum_p M_p(v_p, theta_i, theta_r - alpha_p) N_p(phi)
//   density per d(theta_r) d(phi) = S cos(theta_r)            (SPEC s7)
//
// - M_p: Eq. 7, evaluated in log space (csch and I0 overflow for small v).
// - N_p: Eq. 10, N_p(phi) = 1/2 int_{-1}^{1} A(p, h) D_p(phi - Phi(p, h)) dh,
//   with the Gaussian detector of Eq. 11, D_p = sum_k g(beta_p; phi - 2 pi k).
// - A(p, h): Eq. 13, (1 - f)^2 f^(p-1) T^p, f of Eq. 14,
//   f = F(eta, arccos(cos theta_d cos(arcsin h))), T as published
//   (exp(-2 mu_a' (1 + cos 2 gamma_t)), mu_a' = mu_a / cos theta_t) or with the
//   chord correction; gamma_t from the Bravais index eta'(theta_d), theta_t
//   from sin theta_t = sin theta_d / eta (the text names neither; theta_d is
//   what Eq. 14 uses, and it reduces to SPEC s7 on the specular cone).
// - A(0, h): Eq. 12 as published, F(eta, arccos(wi . wr) / 2), a function of
//   the exit direction, not of h (r_fresnel=half_angle, the default), or
//   Eq. 14 like the other orders (r_fresnel=per_h). They agree for v, beta -> 0;
//   only per_h conserves energy exactly for rough fibers.
// - Lobes: 0..L-2 one order each; lobe L-1 sums p >= L-1: orders up to the
//   first P (<= Deon2011Params::max_order, default 40) after which the remaining energy, computed in
//   closed form per h (sum_{p>P} A = (1-f)^2 f^P T^(P+1) / (1 - f T)), is
//   below 1e-6, then that remainder spread uniformly in phi (d'Eon's and
//   pbrt's residual term), with the last lobe's M. Energy is exact; only the
//   remainder's phi shape is approximate.
// - theta_d of N_p: the exit direction's (published) or, with
//   Deon2011Params::specular_theta_d, the specular cone's -theta_i, which makes
//   the model the simulator's exit_blur exactly (SPEC s3).
// - Per-lobe parameters: v_p = beta_long_p^2, beta_p = beta_azim_p, alpha_p
//   (lists indexed by p, the last entry for every larger p).
// - Limits: beta_long = 0 gives M_p = delta(theta_r - alpha_p + theta_i) /
//   cos(theta_i) (SPEC s7), beta_azim = 0 the smooth N_p (exact bins through
//   caustics); bin_probabilities() handles both exactly. density() floors
//   beta at 1e-3 rad instead, since deltas cannot be evaluated pointwise.
#include <memory>
#include <vector>

#include "analytic/azimuthal_lobes.h"
#include "analytic/longitudinal_lobes.h"
#include "analytic/model.h"

namespace fiberlab::analytic {

namespace deon2011 {

// Eq. 7, M_p and its parts (longitudinal_lobes.h): log M_p(v, theta_i, theta_r) =
//   log csch(1/v) - log(2v) - sin(theta_i) sin(theta_r)/v + log I0(cos(theta_i) cos(theta_r)/v).
using longitudinal::log_csch;
using longitudinal::log_I0;
inline double log_M_p(double v, double theta_i, double theta_r) {
  return longitudinal::vmf_log_M_p(v, theta_i, theta_r);
}
inline double M_p(double v, double theta_i, double theta_r) { return longitudinal::vmf_M_p(v, theta_i, theta_r); }
// Eq. 11: the Gaussian detector, unit-integral over one period (azimuthal_lobes.h).
inline double D_p(double beta, double phi) { return azimuthal::wrapped_gaussian(beta, phi); }
// Eq. 10 by Gauss-Legendre of `order` points over h (paper: 35), per channel.
// r_half_angle: the R order uses Eq. 12 with the exit direction given by
// (theta_i, theta_r, phi) (theta_d = (theta_r - theta_i) / 2).
struct Fiber {
  double eta = 1.55;
  std::vector<double> sigma_a{0.0};
  Absorption absorption = Absorption::Published;
  bool r_half_angle = true;
};
void N_p(int p, double beta, const Fiber& fiber, double theta_i, double theta_r, double phi,
         int order, std::vector<double>& out);
// Eq. 12's Fresnel term: F(eta, arccos(wi . wr) / 2).
double F_half_angle(double eta, double theta_i, double theta_r, double phi);

}  // namespace deon2011

// The model's parameters (its table, deon2011_info() in deon2011.cpp, binds
// `--set` keys to these fields). Lists are indexed by lobe p, the last entry
// for every larger p; angles in radians. The defaults are neutral values for
// code that builds the model directly (tests); the command line's are the
// table's.
struct Deon2011Params {
  double eta = 1.55;
  std::vector<double> sigma_a{0.0, 0.0, 0.0};  // 1/R per channel
  std::vector<double> beta_long{0.0};          // v_p = beta_long_p^2
  std::vector<double> beta_azim{0.0};          // Gaussian detector sd beta_p
  std::vector<double> alpha{0.0};              // shift of theta_r per p
  Absorption absorption = Absorption::Published;
  int lobes = 4;  // lobes 0..L-2 separately, lobe L-1 = every p >= L-1
  // Gauss-Legendre order of the N_p integral over h (density()).
  int quadrature_order = 35;
  // The R lobe's Fresnel term. true = Eq. 12 as published, F(eta,
  // arccos(wi.wr)/2) at the exit direction; false = Eq. 14 per h,
  // F(eta, arccos(cos theta_d cos gamma_i)) (`r_fresnel=half_angle|per_h`).
  bool r_half_angle_fresnel = true;
  // Highest order p traced explicitly in the last lobe; the energy of the
  // orders above goes to the uniform residual (`max_order=N`).
  int max_order = 40;
  // theta_d at which N_p is evaluated. false (published): theta_d =
  // (theta_r - theta_i)/2 of the exit direction; true: theta_d = -theta_i,
  // the specular cone's, so that S = M_p(theta_r) N_p(phi) is a product:
  // exactly the simulator's `exit_blur` (SPEC s3) (`n_theta_d=exit|specular`).
  bool specular_theta_d = false;
};

class Deon2011 : public Model {
 public:
  explicit Deon2011(Deon2011Params params);
  std::string name() const override { return "deon2011"; }
  int lobes() const override { return params_.lobes; }
  void density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
               std::vector<double>& out) const override;
  // Bin integrals: M_p exactly by composite Gauss-Legendre (panels below
  // sqrt(v)/3) against a Chebyshev interpolant in theta_r of the phi-bin
  // integrals of N_p, which are exact in phi (the Gaussian detector's bin
  // mass in closed form: erfc per node, or for wide detectors its Fourier
  // series, Eq. 11's coefficients exp(-n^2 beta^2 / 2)) and use composite
  // Gauss-Legendre over gamma_i with panels on which Phi moves by at most
  // min(4 beta_p, 1). The Fourier series stops, per order p, at the term
  // beyond which the rest provably changes no bin by more than 1e-13 (the
  // order's energy times the tail of the coefficients, see FourierSums in
  // bin_integration.h). The R lobe's azimuthal shape under Eq. 12,
  // G_0 = D_0 * |cos(psi/2)| / 4, is its closed Fourier series (beta >= 0.005
  // rad; truncated where the terms are below 1e-17) or a quadrature below.
  std::vector<double> bin_probabilities(const BinGrid& grid, double theta_i,
                                        double phi_i) const override;
  //
  // Accuracy (measured against set_refinement(2) and (4), and max_order 100,
  // on 90 x 180 bins, sigma_a = 0, the hardest case): lobes R, TT, TRT agree
  // to < 1e-10 absolute per bin; the p >= 3 lobe to < 1e-7 for theta_i <= 60
  // deg and ~1e-6 at theta_i = 85 deg (theta_d -> 90 deg makes eta' vary
  // fast in theta_r), against a 1e8-photon Monte Carlo standard error of
  // 1e-7 .. 2e-6 in those bins. Energy: the sum over all bins is 1 to 1e-10
  // (r_fresnel=per_h, sigma_a = 0), to ~5e-6 at theta_i = 85 deg, beta = 2 deg.
  // Zero roughness reproduces the exact smooth cylinder bin for bin.
  // Tested against a slow direct evaluation of Eqs. 7 and 10-12 at 64 bins
  // of the four lobes (beta_azim 5 and 2 deg): within 1e-11 absolute.
  // Its cost grows for narrow detectors (the erfc deposit) and for white
  // fibers (many orders): docs/PERFORMANCE.md.
  //
  // Multiplies every node density of bin_probabilities() (Chebyshev nodes,
  // h panels, M panels) by `factor`, to measure convergence (tests).
  void set_refinement(double factor) { refine_ = factor; }
  int max_order() const { return max_order_; }
  // Highest order traced explicitly in the last lobe (default 40).
  void set_max_order(int p) { max_order_ = p; }

 private:
  Deon2011Params params_;
  double refine_ = 1.0;
  int max_order_;
};

std::unique_ptr<Model> make_deon2011(const Deon2011Params& params);

}  // namespace fiberlab::analytic
