#pragma once
// Chiang, Bitterli, Tappan, Burley 2016, "A Practical and Controllable Hair
// and Fur Model for Production Path Tracing" (Computer Graphics Forum 35(2)),
// the model behind pbrt-v3/v4's HairBxDF, Mitsuba 3's `hair` and Cycles'
// Principled Hair "Chiang", as a far-field BCSDF (averaged over the offset h):
//
//   S(theta_i, theta_r, phi) = sum_{p<3} M_p(v_p, theta_i'_p, theta_r) N_p(phi)
//                              + M_p(v_2, theta_i, theta_r) E_3 / (2 pi)
//   N_p(phi) = 1/2 int_{-1}^{1} A_p(theta_i, h) L_s(phi - Phi(p, h)) dh
//   E_3      = 1/2 int_{-1}^{1} A_3(theta_i, h) dh
//   density per d(theta_r) d(phi) = S cos(theta_r)                (SPEC s7)
//
// - M_p: d'Eon et al. 2011 Eq. 7 (longitudinal_lobes.h, as deon2011 uses it).
// - Roughness (Chiang et al. 2016, their longitudinal and azimuthal
//   roughness mappings, fitted so that beta in [0, 1] feels linear):
//     v   = (0.726 beta_m + 0.812 beta_m^2 + 3.7 beta_m^20)^2   for R,
//     v_1 = v / 4 (TT),  v_2 = 4 v (TRT and the residual);
//     s   = sqrt(pi/8) (0.265 beta_n + 1.194 beta_n^2 + 5.372 beta_n^22).
// - L_s: the logistic distribution of scale s trimmed to [-pi, pi] (and
//   renormalised), applied to the azimuth difference wrapped to [-pi, pi].
// - A_p: 3D Fresnel f = F(eta, acos(cos theta_i cos gamma_i)) at the entry,
//   A_0 = f, A_p = (1 - f)^2 f^(p-1) T^p, and the residual lobe
//   A_3 = sum_{p>=3} = (1 - f)^2 f^2 T^3 / (1 - f T) (p_max = 3), with
//   T = exp(-sigma_a 2 cos(gamma_t) / cos(theta_t)): the chord (SPEC s7),
//   gamma_i = asin h, sin gamma_t = h / eta'(theta_i), sin theta_t =
//   sin theta_i / eta. These are exactly the smooth cylinder's terms
//   (cylinder::Attenuation with Absorption::Chord).
// - Phi(p, h) = 2 p gamma_t - 2 gamma_i + p pi (SPEC s7).
// - Cuticle tilt: M_p of lobe p sees the incident inclination rotated by a
//   multiple 2^k alpha of the tilt: theta_i'_0 = theta_i + 2 alpha,
//   theta_i'_1 = theta_i - alpha, theta_i'_2 = theta_i - 4 alpha (taken
//   through sin and |cos| when the rotation passes the pole, as pbrt does);
//   the residual is not rotated. The lobes' centres thus move to
//   theta_r = -theta_i - 2 alpha (R), -theta_i + alpha (TT), -theta_i +
//   4 alpha (TRT): SPEC s7's default shifts for scale_tilt = alpha.
//   Sign: alpha > 0 is SPEC's scale_tilt > 0 (scales tilted towards the
//   root, R towards the root). pbrt-v4 rotates its wo by -2 alpha (R),
//   +alpha (TT), +4 alpha (TRT); read with its wo as our wi (below) that
//   moves R to theta_r = -theta_i + 2 alpha, so pbrt-v4's alpha is minus
//   this one (pbrt-v3, which rotated wi by +2 alpha, has this sign).
// - Frames: pbrt evaluates f(wo, wi) for a fixed wo whose inclination and
//   offset h enter A_p, and integrates over wi. fiberlab fixes the light and
//   integrates over exits, so pbrt's wo plays our wi: A_p, eta' and h belong
//   to the incident side (theta_i, gamma_i = asin h), and phi is our
//   relative azimuth phi_r - phi_i. N_p therefore does not depend on theta_r
//   and, since every M_p integrates to 1 over the exit sphere and L_s to 1
//   over phi, the white furnace (sigma_a = 0) is exact: sum_p A_p = 1.
// - Lobes: lobes 0, 1, 2 are R, TT, TRT; lobe 3 is the residual p >= 3
//   (the model cannot split it further, so at most 4 lobes). With fewer
//   lobes the last one sums every higher order.
//
// Limits: beta_n = 0 gives L_s = delta (the smooth cylinder's N_p, exact
// bins through the caustics); beta_m -> 0 gives M_p -> delta(theta_r +
// theta_i'_p) / cos(theta_i'_p), used below v = 1e-10 (beta_m < 1.4e-5).
// density() floors v at 1e-8 and s at 1e-6 (deltas cannot be evaluated
// pointwise); bin_probabilities() is exact in both limits.
#include <memory>
#include <vector>

#include "analytic/azimuthal_lobes.h"
#include "analytic/model.h"

namespace fiberlab::analytic {

namespace chiang2016 {

// Longitudinal variance of the R lobe from beta_m in [0, 1].
double longitudinal_variance(double beta_m);
// Logistic scale s from beta_n in [0, 1].
double logistic_scale(double beta_n);
// The logistic trimmed to [-pi, pi] and its periodic cumulative
// (azimuthal_lobes.h).
using azimuthal::trimmed_logistic;
using azimuthal::trimmed_logistic_cumulative;

// Inverses of the two mappings on [0, 1] (bisection; both are increasing):
// beta_m whose R lobe has sqrt(v) = width, beta_n whose logistic has scale s.
// fiberlab::Error when the value lies beyond beta = 1.
double beta_m_for_width(double width);
double beta_n_for_scale(double s);

}  // namespace chiang2016

// The longitudinal function M_p (`mp=exact|pbrt_v4`): d'Eon 2011 Eq. 7
// exactly (the paper's function), or pbrt-v4's numerics as shipped
// (analytic/pbrt_v4_mp.h).
enum class Chiang2016Mp { Exact, PbrtV4 };

// The model's parameters (its table, chiang2016_info() in chiang2016.cpp,
// binds `--set` keys to these fields; `alpha` is the scale tilt).
struct Chiang2016Params {
  double eta = 1.55;                    // > 1
  std::vector<double> sigma_a{0.0};     // 1/R per channel, >= 0
  double beta_m = 0.3, beta_n = 0.3;    // in [0, 1]
  double alpha = 0.0;                   // scale tilt, radians (sign: see above)
  int lobes = 4;                        // 1..4
  Chiang2016Mp mp = Chiang2016Mp::Exact;
};

class Chiang2016 : public Model {
 public:
  // Throws fiberlab::Error naming the parameter and its allowed range.
  explicit Chiang2016(Chiang2016Params params);
  std::string name() const override { return "chiang2016"; }
  int lobes() const override { return params_.lobes; }
  void density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
               std::vector<double>& out) const override;
  // Exact factorisation (N_p does not depend on theta_r): bin probability =
  // (integral of M_p cos over the theta bin) x (integral of N_p over the phi
  // bin). theta: composite 8-point Gauss-Legendre, panels <= sqrt(v)/3, over
  // the peak +- 12 sqrt(v) (beyond it M_p cos < e^-70 of its peak). phi:
  // the trimmed logistic's bin mass in closed form per node over h; nodes
  // are composite Gauss-Legendre over gamma_i, with panels on which Phi
  // moves by at most 2 s wherever Phi is within 40 s of a bin edge (the
  // logistic's tail beyond 40 s is e^-40) and panels of pi/64 elsewhere.
  // Convergence (tests): refinement 2 changes no bin by more than 1e-12.
  std::vector<double> bin_probabilities(const BinGrid& grid, double theta_i,
                                        double phi_i) const override;

  // Lobe energies (1/2) int A dh per [lobe * C + c], by the same nodes.
  std::vector<double> lobe_energies(double theta_i) const;
  // Multiplies the node density of bin_probabilities() (tests).
  void set_refinement(double factor) { refine_ = factor; }
  const Chiang2016Params& params() const { return params_; }

 private:
  // Incident inclination seen by M_p of order p (tilt rotation), p <= 3.
  double rotated_theta_i(int p, double theta_i) const;
  double variance(int p) const;
  Chiang2016Params params_;
  double v_, s_;
  double refine_ = 1.0;
};

// Chord absorption always (the model's own).
std::unique_ptr<Model> make_chiang2016(const Chiang2016Params& params);

}  // namespace fiberlab::analytic
