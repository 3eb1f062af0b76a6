#include "analytic/deon2011.h"

#include <fmt/core.h>
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cmath>
#include <optional>

#include "analytic/azimuthal_lobes.h"
#include "analytic/bin_integration.h"
#include "analytic/longitudinal_lobes.h"
#include "analytic/model_registry.h"
#include "analytic/quadrature.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "common/fresnel.h"
#include "common/units.h"

namespace fiberlab::analytic {
namespace deon2011 {

double F_half_angle(double eta, double theta_i, double theta_r, double phi) {
  const double x = std::sin(theta_i) * std::sin(theta_r) +
                   std::cos(theta_i) * std::cos(theta_r) * std::cos(phi);
  // cos(arccos(x) / 2) = sqrt((1 + x) / 2).
  return fresnel_dielectric(std::sqrt(std::clamp(0.5 * (1.0 + x), 0.0, 1.0)), eta);
}

void N_p(int p, double beta, const Fiber& fiber, double theta_i, double theta_r, double phi,
         int order, std::vector<double>& out) {
  const int C = static_cast<int>(fiber.sigma_a.size());
  out.assign(C, 0.0);
  const double theta_d = 0.5 * (theta_r - theta_i);
  const cylinder::Attenuation att(fiber.eta, theta_d, fiber.sigma_a, fiber.absorption);
  const GaussLegendre& gl = gauss_legendre(order);
  std::vector<double> a(C);
  const bool half = p == 0 && fiber.r_half_angle;
  const double f_half = half ? F_half_angle(fiber.eta, theta_i, theta_r, phi) : 0.0;
  for (int q = 0; q < order; ++q) {
    const double h = gl.x[q];
    const double g = std::asin(h);
    const double d = D_p(beta, phi - cylinder::Phi(p, g, att.eta_p()));
    if (half) {
      for (int c = 0; c < C; ++c) out[c] += 0.5 * gl.w[q] * f_half * d;
    } else {
      att.A(p, g, a.data());
      for (int c = 0; c < C; ++c) out[c] += 0.5 * gl.w[q] * a[c] * d;
    }
  }
}

}  // namespace deon2011

namespace {
constexpr double kSmoothBeta = 1e-4;   // beta_azim below this: the smooth N_p
constexpr double kDeltaBeta = 1e-7;    // beta_long below this: M_p is a delta
constexpr double kDensityFloor = 1e-3; // density(): floor of both betas
constexpr double kResidualTol = 1e-6;  // energy left to the uniform residual
// Per order and theta_r node: bound on a phi bin's change from the Fourier
// terms left out (see FourierSums, bin_integration.h).
constexpr double kFourierTol = 1e-13;

// The last order traced explicitly when judged at exit inclination theta_r
// (cylinder::last_order with kResidualTol).
int last_explicit_order(const Deon2011Params& params, double theta_i, double theta_r, int p_first, int max_order) {
  std::vector<double> res;
  const cylinder::Attenuation att(params.eta, 0.5 * (theta_r - theta_i), params.sigma_a, params.absorption);
  return cylinder::last_order(att, p_first, kResidualTol, max_order, res);
}

// One group of orders sharing M_p and the detector: a single p, or (open)
// every p >= p0 of the last lobe.
struct Term {
  int lobe, p0, p1;  // orders p0..p1 traced explicitly
  bool residual;     // plus every p > p1, spread uniformly in phi
  bool coarse;       // high orders (p > kFineOrders): base theta resolution
  double v, alpha, beta;
};
// Orders of the last lobe above this get the base Chebyshev count in theta_r:
// their energy is small, so their (equally sharp) features need less
// relative accuracy.
constexpr int kFineOrders = 20;

// Lobes 0..L-2 one order each; the last lobe one term per order whose
// parameters still differ, then one open term up to the last explicit
// order, judged at the specular direction, the M_p peak and 3 sigma either
// side, and fixed for the whole theta_r range so that N_p stays smooth in
// theta_r.
std::vector<Term> lobe_terms(const Deon2011Params& params, double theta_i, int max_order) {
  const int L = params.lobes;
  const int list_len = static_cast<int>(std::max({params.beta_long.size(), params.beta_azim.size(), params.alpha.size()}));
  std::vector<Term> terms;
  auto make_term = [&](int lobe, int p, int p1, bool residual, bool coarse) {
    const double bl = for_lobe(params.beta_long, p);
    return Term{lobe, p, p1, residual, coarse, bl * bl, for_lobe(params.alpha, p), for_lobe(params.beta_azim, p)};
  };
  for (int l = 0; l < L - 1; ++l) terms.push_back(make_term(l, l, l, false, false));
  const int p_open = std::max(L - 1, list_len - 1);
  for (int p = L - 1; p < p_open; ++p) terms.push_back(make_term(L - 1, p, p, false, false));
  const double bl = for_lobe(params.beta_long, p_open), al = for_lobe(params.alpha, p_open);
  std::vector<double> probes{-theta_i};
  if (!params.specular_theta_d)
    for (double d : {-3.0, 0.0, 3.0}) probes.push_back(al - theta_i + d * bl);
  int p_last = p_open;
  for (double tr : probes)
    p_last = std::max(p_last, last_explicit_order(params, theta_i, std::clamp(tr, -kPi / 2, kPi / 2), p_open, max_order));
  if (p_last <= kFineOrders || p_open > kFineOrders) {
    terms.push_back(make_term(L - 1, p_open, p_last, true, p_open > kFineOrders));
  } else {
    terms.push_back(make_term(L - 1, p_open, kFineOrders, false, false));
    terms.push_back(make_term(L - 1, kFineOrders + 1, p_last, true, true));
  }
  return terms;
}

// Eq. 12's Fresnel term F(eta, arccos(wi . wr) / 2) (deon2011::F_half_angle)
// at every phi point k of a theta_r: wi . wr = a + b cos(phi_k) with
// a = sin theta_i sin theta_r, b = cos theta_i cos theta_r, and
// cos(arccos(x) / 2) = sqrt((1 + x) / 2). SIMD lanes (xsimd) through the
// shared generic Fresnel (common/fresnel.h).
void half_angle_fresnel(double a, double b, const std::vector<double>& cos_phi, double eta,
                        std::vector<double>& out) {
  using Batch = xsimd::batch<double>;
  constexpr std::size_t W = Batch::size;
  const std::size_t n = cos_phi.size();
  out.resize(n);
  std::size_t k = 0;
  for (; k + W <= n; k += W) {
    const Batch x = Batch(a) + Batch(b) * Batch::load_unaligned(cos_phi.data() + k);
    const Batch u = xsimd::sqrt(xsimd::min(Batch(1.0), xsimd::max(Batch(0.0), 0.5 * (1.0 + x))));
    fresnel_dielectric(u, Batch(eta)).store_unaligned(out.data() + k);
  }
  for (; k < n; ++k)
    out[k] = fresnel_dielectric(std::sqrt(std::clamp(0.5 * (1.0 + a + b * cos_phi[k]), 0.0, 1.0)), eta);
}

// G_0, the R lobe's azimuthal shape under Eq. 12 (azimuthal_lobes.h): the
// smooth |cos(phi/2)| / 4 below kSmoothBeta.
double G0(double phi, double beta, double refine) {
  if (beta < kSmoothBeta) return std::abs(std::cos(0.5 * phi)) * 0.25;
  return beta >= azimuthal::kHalfAngleSeriesBeta ? azimuthal::half_angle_r_shape_series(phi, beta)
                                                 : azimuthal::half_angle_r_shape_quadrature(phi, beta, refine);
}

// The R lobe with Eq. 12's Fresnel, F(eta, arccos(wi . wr) / 2), which
// depends on the exit direction: its phi-bin integrals at one theta_r,
// sum_q F(theta_r, phi_jq) G_0(phi_jq) w_jq over kPhiOrder Gauss points of
// every phi bin (G_0 and cos(phi_jq) tabulated once per incidence).
class HalfAngleRLobe {
 public:
  HalfAngleRLobe(double eta, double beta, double theta_i, int np, double refine)
      : eta_(eta), np_(np), sin_i_(std::sin(theta_i)), cos_i_(std::cos(theta_i)) {
    const GaussLegendre& glp = gauss_legendre(kPhiOrder);
    const double dphi = kTwoPi / np;
    std::vector<double> g0(static_cast<std::size_t>(np) * kPhiOrder);
    cos_ph_.resize(g0.size());
    for (int j = 0; j < np; ++j)
      for (int q = 0; q < kPhiOrder; ++q) {
        const double ph = -kPi + (j + 0.5) * dphi + 0.5 * dphi * glp.x[q];
        g0[j * kPhiOrder + q] = G0(ph, beta, refine);
        cos_ph_[j * kPhiOrder + q] = std::cos(ph);
      }
    gw_.resize(g0.size());
    for (std::size_t jq = 0; jq < g0.size(); ++jq) gw_[jq] = 0.5 * dphi * glp.w[jq % kPhiOrder] * g0[jq];
  }
  // row[j]: the lobe's mass in phi bin j per unit theta_r at theta_r.
  void row(double theta_r, std::vector<double>& row) const {
    half_angle_fresnel(sin_i_ * std::sin(theta_r), cos_i_ * std::cos(theta_r), cos_ph_, eta_, fresnel_);
    row.assign(np_, 0.0);
    for (int j = 0; j < np_; ++j)
      for (int q = 0; q < kPhiOrder; ++q) row[j] += fresnel_[j * kPhiOrder + q] * gw_[j * kPhiOrder + q];
  }

 private:
  static constexpr int kPhiOrder = 6;
  double eta_;
  int np_;
  double sin_i_, cos_i_;
  std::vector<double> cos_ph_, gw_;  // [j * kPhiOrder + q]
  mutable std::vector<double> fresnel_;
};

// Phi-bin integrals of sum_{p in term} N_p at exit inclination theta_r
// (Eq. 10 with the detector of Eq. 11): nb[j * C + c].
class AzimuthalBins {
 public:
  AzimuthalBins(const Deon2011Params& params, double theta_i, int np, double refine, const HalfAngleRLobe* r_lobe)
      : params_(params), theta_i_(theta_i), np_(np), C_(static_cast<int>(params.sigma_a.size())),
        refine_(refine), r_lobe_(r_lobe), a_(C_) {}

  void operator()(const Term& t, double theta_r, std::vector<double>& nb) {
    nb.assign(static_cast<std::size_t>(np_) * C_, 0.0);
    const cylinder::Attenuation att(params_.eta, 0.5 * (theta_r - theta_i_), params_.sigma_a,
                                    params_.absorption);
    const int n_fourier = fourier_terms(t.beta);
    fourier_.clear(C_);
    for (int p = t.p0; p <= t.p1; ++p) add_order(att, p, t.beta, theta_r, n_fourier, nb);
    if (n_fourier > 0)
      fourier_bins_.add(fourier_, n_fourier, t.beta, kFourierTol / (refine_ * refine_), np_, C_, nb);
    if (t.residual) {
      cylinder::energy_beyond(att, t.p1, res_);
      for (int j = 0; j < np_; ++j)
        for (int c = 0; c < C_; ++c) nb[static_cast<std::size_t>(j) * C_ + c] += res_[c] / np_;
    }
  }

 private:
  // Wide detectors: deposit through the Fourier series of Eq. 11 (terms up
  // to g_n < 1e-17) unless it is 64x longer than the erfc window per node
  // (the same sum either way; the Fourier sum costs per term, the erfc
  // deposit per bin of the window). 0: the erfc deposit.
  int fourier_terms(double beta) const {
    if (!(beta >= kSmoothBeta)) return 0;
    const int n_max = GaussianFourierBins::terms(beta);
    const double window = 2.0 * azimuthal::kGaussianWindow * beta / (kTwoPi / np_);
    return n_max <= 64.0 * window ? n_max : 0;
  }
  // Order p's phi-bin integrals into nb, or its nodes into the Fourier sums.
  void add_order(const cylinder::Attenuation& att, int p, double beta, double theta_r, int n_fourier,
                 std::vector<double>& nb) {
    if (p == 0 && r_lobe_) {
      r_lobe_->row(theta_r, row_);
      for (int j = 0; j < np_; ++j)
        for (int c = 0; c < C_; ++c) nb[static_cast<std::size_t>(j) * C_ + c] += row_[j];
      return;
    }
    if (beta < kSmoothBeta) return cylinder::add_smooth_lobe(att, p, np_, nb);
    // Panels over which Phi moves by up to 4 beta: 8 Gauss points resolve the
    // detector to ~1e-12 there (checked against beta / 4 panels).
    cylinder::panel_nodes(p, att.eta_p(), std::min(4.0 * beta, 1.0) / refine_, 8, nodes_, n_fourier == 0);
    if (n_fourier > 0) return add_fourier_nodes(att, p, nodes_, fourier_);
    const azimuthal::GaussianCdf cdf(beta);
    for (const auto& nd : nodes_) {
      att.A(p, nd.gamma, a_.data());
      for (int c = 0; c < C_; ++c) a_[c] *= nd.weight;
      deposit_wrapped(cdf, nd.phi, beta, azimuthal::kGaussianWindow, false, a_.data(), C_, np_, nb);
    }
  }

  const Deon2011Params& params_;
  double theta_i_;
  int np_, C_;
  double refine_;
  const HalfAngleRLobe* r_lobe_;  // the R lobe under Eq. 12, or null
  std::vector<cylinder::PathNode> nodes_;
  std::vector<double> a_, res_, row_;
  FourierSums fourier_;
  GaussianFourierBins fourier_bins_;
};

// log (M_p cos theta_r) of a term at theta_r.
double log_mp_cos(const Term& t, double theta_i, double theta_r) {
  return longitudinal::vmf_log_M_p(t.v, theta_i, theta_r - t.alpha) + std::log(std::max(std::cos(theta_r), 1e-300));
}

// Support of M_p cos(theta_r): where it is within e^-30 (1e-13) of its
// maximum, found on a 512-step scan of [-pi/2, pi/2] and widened by a step;
// what lies beyond is dropped (below 1e-12 of the lobe).
std::pair<double, double> mp_support(const Term& t, double theta_i) {
  constexpr int kScan = 512;
  const double step = kPi / kScan;
  const double peak_at = std::clamp(t.alpha - theta_i, -kPi / 2, kPi / 2);
  double peak = log_mp_cos(t, theta_i, peak_at);
  std::vector<double> lw(kScan + 1);
  for (int s = 0; s <= kScan; ++s) peak = std::max(peak, lw[s] = log_mp_cos(t, theta_i, -kPi / 2 + s * step));
  int s0 = kScan, s1 = 0;
  for (int s = 0; s <= kScan; ++s)
    if (lw[s] > peak - 30.0) s0 = std::min(s0, s), s1 = std::max(s1, s);
  return {std::max(-kPi / 2, std::min(-kPi / 2 + (s0 - 1) * step, peak_at - step)),
          std::min(kPi / 2, std::max(-kPi / 2 + (s1 + 1) * step, peak_at + step))};
}

// Quadrature nodes of M_p cos(theta_r) over each theta bin within [lo, hi],
// panels below sqrt(v)/3, split at theta_r = -theta_i (where Eq. 12's
// Fresnel term has a kink in the forward direction).
std::vector<ThetaNode> mp_nodes(const Term& t, double theta_i, const BinGrid& grid, double lo, double hi,
                                double refine) {
  std::vector<ThetaNode> tp;
  const double max_len = std::min(std::sqrt(t.v) / 3.0, 0.05) / refine;
  theta_panel_nodes(grid.theta_edges, lo, hi, -theta_i, max_len, [&](int i, double tr, double w) {
    const double wm = w * std::exp(log_mp_cos(t, theta_i, tr));
    if (wm > 0.0) tp.push_back({i, tr, wm});
  });
  return tp;
}

// Adds weight[i] times the phi-bin integrals nb to every theta bin i of a
// lobe (rows of np * C).
void add_rows(const std::vector<double>& weight, const std::vector<double>& nb, double* lobe_out) {
  for (std::size_t i = 0; i < weight.size(); ++i) {
    if (weight[i] == 0.0) continue;
    double* o = &lobe_out[i * nb.size()];
    for (std::size_t x = 0; x < nb.size(); ++x) o[x] += weight[i] * nb[x];
  }
}


// Chebyshev points for N_p's theta_r dependence over a support `width`
// wide. Its features (caustics moving with theta_d) are about beta_azim wide
// in phi: more points for narrow detectors (8x the base count at 2 deg
// reaches 1e-7 of the bin probabilities against set_refinement(4)). Orders
// p > 2 move their caustics faster with theta_d: twice the points.
int chebyshev_points(const Term& t, double width, double refine) {
  const double narrow = t.coarse ? 1.0
                                 : std::clamp(deg_to_rad(16.0) / std::max(t.beta, 1e-12), 1.0, 16.0) *
                                       (t.p1 > 2 ? 2.0 : 1.0);
  return std::clamp(static_cast<int>(std::ceil(refine * narrow * (4.0 + 8.0 * width))), 3, 200);
}

}  // namespace

Deon2011::Deon2011(Deon2011Params params) : params_(std::move(params)), max_order_(params_.max_order) {
  auto bad = [](const std::string& what) { throw Error("deon2011: " + what); };
  if (!(params_.eta > 1.0)) bad(fmt::format("eta = {} must be > 1", params_.eta));
  if (params_.lobes < 1) bad("lobes must be >= 1");
  if (params_.sigma_a.empty()) bad("sigma_a needs at least one channel");
  if (params_.beta_long.empty() || params_.beta_azim.empty() || params_.alpha.empty())
    bad("beta_long, beta_azim and alpha need at least one entry");
  for (double b : params_.beta_long)
    if (!(b >= 0.0) || !std::isfinite(b)) bad(fmt::format("beta_long = {} must be >= 0", b));
  for (double b : params_.beta_azim)
    if (!(b >= 0.0) || !std::isfinite(b)) bad(fmt::format("beta_azim = {} must be >= 0", b));
  for (double s : params_.sigma_a)
    if (!(s >= 0.0) || !std::isfinite(s)) bad(fmt::format("sigma_a = {} must be >= 0", s));
  if (params_.quadrature_order < 1) bad("quadrature_order must be >= 1");
  if (params_.max_order < 0) bad("max_order must be >= 0");
}

void Deon2011::density(int lobe, double theta_i, double, double theta_r, double phi,
                       std::vector<double>& out) const {
  const int C = static_cast<int>(params_.sigma_a.size());
  out.assign(C, 0.0);
  const int L = params_.lobes;
  const deon2011::Fiber fiber{params_.eta, params_.sigma_a, params_.absorption,
                              params_.r_half_angle_fresnel};
  const double cos_r = std::cos(theta_r);
  // theta_r at which N_p is evaluated (its theta_d = (theta_rn - theta_i) / 2).
  const double theta_rn = params_.specular_theta_d ? -theta_i : theta_r;
  int p_end = lobe;
  std::vector<double> res;
  if (lobe >= L - 1) {
    const cylinder::Attenuation att(params_.eta, 0.5 * (theta_rn - theta_i), params_.sigma_a,
                                    params_.absorption);
    p_end = cylinder::last_order(att, lobe, kResidualTol, max_order_, res);
  }
  std::vector<double> n;
  for (int p = lobe; p <= p_end; ++p) {
    const double bl = std::max(for_lobe(params_.beta_long, p), kDensityFloor);
    const double ba = std::max(for_lobe(params_.beta_azim, p), kDensityFloor);
    const double m = deon2011::M_p(bl * bl, theta_i, theta_r - for_lobe(params_.alpha, p));
    // Eq. 10 quadrature: the paper's 35 points suffice for beta >= 2 deg;
    // below, scale the order as 1 / beta.
    const int order = std::min(
        4000, std::max(params_.quadrature_order,
                       static_cast<int>(std::ceil(params_.quadrature_order * deg_to_rad(2.0) / ba))));
    deon2011::N_p(p, ba, fiber, theta_i, theta_rn, phi, order, n);
    for (int c = 0; c < C; ++c) out[c] += m * n[c] * cos_r;
  }
  if (lobe >= L - 1) {
    const double bl = std::max(for_lobe(params_.beta_long, p_end), kDensityFloor);
    const double m = deon2011::M_p(bl * bl, theta_i, theta_r - for_lobe(params_.alpha, p_end));
    for (int c = 0; c < C; ++c) out[c] += m * res[c] / kTwoPi * cos_r;
  }
}

std::vector<double> Deon2011::bin_probabilities(const BinGrid& grid, double theta_i,
                                                double) const {
  const int nt = grid.n_theta(), np = grid.n_phi(), L = params_.lobes;
  const int C = static_cast<int>(params_.sigma_a.size());
  std::vector<double> out(static_cast<std::size_t>(L) * nt * np * C, 0.0);
  const std::vector<Term> terms = lobe_terms(params_, theta_i, max_order_);
  std::optional<HalfAngleRLobe> r_lobe;
  if (params_.r_half_angle_fresnel && terms.front().p0 == 0)
    r_lobe.emplace(params_.eta, terms.front().beta, theta_i, np, refine_);
  AzimuthalBins azimuthal(params_, theta_i, np, refine_, r_lobe ? &*r_lobe : nullptr);
  std::vector<double> nb, weight(nt), row;
  for (const Term& t : terms) {
    double* lobe_out = &out[static_cast<std::size_t>(t.lobe) * nt * np * C];
    if (t.v < kDeltaBeta * kDeltaBeta) {
      // M_p -> delta(theta_r - alpha + theta_i) / cos(theta_i): all of it in one theta bin.
      const double tr = t.alpha - theta_i;
      if (std::abs(tr) > kPi / 2) continue;  // shifted off the sphere (documented loss)
      const double w = std::cos(tr) / std::cos(theta_i);
      azimuthal(t, params_.specular_theta_d ? -theta_i : tr, nb);
      const int i = grid.theta_bin(tr);
      for (std::size_t k = 0; k < nb.size(); ++k) lobe_out[static_cast<std::size_t>(i) * np * C + k] += w * nb[k];
      continue;
    }
    const auto [lo, hi] = mp_support(t, theta_i);
    const std::vector<ThetaNode> tp = mp_nodes(t, theta_i, grid, lo, hi, refine_);
    if (r_lobe && t.p0 == 0 && t.p1 == 0 && !t.residual && !params_.specular_theta_d) {
      // R with Eq. 12: F depends on (theta_r, phi) itself: direct 2D quadrature.
      for (const ThetaNode& pt : tp) {
        r_lobe->row(pt.theta, row);
        for (int j = 0; j < np; ++j) {
          double* o = &lobe_out[(static_cast<std::size_t>(pt.i) * np + j) * C];
          for (int c = 0; c < C; ++c) o[c] += pt.w * row[j];
        }
      }
      continue;
    }
    if (params_.specular_theta_d) {
      // N_p does not depend on theta_r: one evaluation, times int_bin M cos.
      azimuthal(t, -theta_i, nb);
      std::fill(weight.begin(), weight.end(), 0.0);
      for (const ThetaNode& pt : tp) weight[pt.i] += pt.w;
      add_rows(weight, nb, lobe_out);
      continue;
    }
    // N_p at Chebyshev points in theta_r, interpolated: each theta bin takes
    // sum_k (int_bin M_p cos l_k) N_p(x_k).
    const ChebyshevLine cheb(lo, hi, chebyshev_points(t, hi - lo, refine_));
    const std::vector<double> mom = cheb.moments(tp, nt);
    for (int k = 0; k < cheb.size(); ++k) {
      azimuthal(t, cheb.node(k), nb);
      for (int i = 0; i < nt; ++i) weight[i] = mom[static_cast<std::size_t>(i) * cheb.size() + k];
      add_rows(weight, nb, lobe_out);
    }
  }
  // The interpolation in theta_r can leave rounding-level negatives (1e-28)
  // where the probability is zero.
  for (double& x : out) x = std::max(x, 0.0);
  return out;
}

std::unique_ptr<Model> make_deon2011(const Deon2011Params& params) {
  return std::make_unique<Deon2011>(params);
}

}  // namespace fiberlab::analytic

// ---- Parameter table and registry entry -------------------------------------------

namespace fiberlab::analytic {

namespace {
std::vector<std::string> deon_approximations(const Deon2011Params& p) {
  std::vector<std::string> out;
  out.push_back(p.absorption == Absorption::Published
                    ? "absorption=published: exp(-4 sigma_a' cos^2 gamma_t) (as published; not the chord)"
                    : "absorption=chord: the chord length (SPEC s7)");
  if (p.r_half_angle_fresnel)
    out.push_back("r_fresnel=half_angle: R lobe Fresnel at half the angle between wi and wr (Eq. 12), "
                  "not per h (Eq. 14)");
  out.push_back(p.specular_theta_d
                    ? "n_theta_d=specular: N_p at theta_d = -theta_i (the simulator's exit_blur exactly)"
                    : "n_theta_d=exit: N_p evaluated at each exit direction's theta_d (per bin), as published");
  out.push_back("M_p: von Mises-Fisher longitudinal lobe (Eq. 7); tilt as a shift of theta_r (alpha)");
  out.push_back(fmt::format("orders p > {} of the last lobe: their energy spread uniformly in phi",
                            p.max_order));
  return out;
}

// The rule from a simulated fiber (physical_defaults.h): circular fibers
// only; the tilt as SPEC s7's shifts; the widths by the calibrated rule in
// d'Eon's theta_r variable.
void deon2011_from_fiber(const PhysicalFiber& f, Deon2011Params& p, FiberMapping& mapping) {
  if (f.eccentricity != 1.0)
    throw Error(fmt::format("model deon2011: circular fibers only; this fiber has eccentricity {:g}",
                            f.eccentricity));
  apply_fiber_basics(f, p);
  p.alpha = tilt_shifts(f.scale_tilt);
  LobeWidths w;
  apply_fiber_roughness(f, w, deon2011_width_calibration(), mapping);
  p.beta_long = w.beta_long;
  p.beta_azim = w.beta_azim;
}
}  // namespace

ModelInfo deon2011_info() {
  using P = Deon2011Params;
  ModelDefinition<P> m;
  m.name = "deon2011";
  m.reference = "d'Eon, Francois, Hill, Letteri, Aubry 2011, An Energy-Conserving Hair Reflectance Model";
  m.params = {
      eta_param<P>(),
      sigma_a_param<P>(),
      beta_long_param<P>("longitudinal width per lobe p: v_p = beta_long_p^2 in M_p (Eq. 7), ~ the sd of theta_r"),
      beta_azim_param<P>("azimuthal width per lobe p: sd of the Gaussian detector D_p (Eq. 11)"),
      alpha_param<P>("shift of theta_r per lobe p (M_p(theta_r - alpha_p))"),
      absorption_param<P>("published"),
      lobes_param<P>(),
      integer_param("quadrature_order", "Gauss-Legendre order of the N_p integral over h (density())", "35",
                    &P::quadrature_order, 1),
      choice_param<P>(
          "r_fresnel", "Fresnel of the R lobe: Eq. 12 half angle (published) or Eq. 14 per h", "half_angle",
          {"half_angle", "per_h"}, [](P& p, int i) { p.r_half_angle_fresnel = i == 0; },
          [](const P& p) { return p.r_half_angle_fresnel ? 0 : 1; }),
      integer_param("max_order", "highest order p traced explicitly in the last lobe", "40", &P::max_order, 1),
      bool_param("n_theta_d", "theta_d of N_p: the exit direction's (published) or the specular cone's", "exit",
                 {"exit", "specular"}, &P::specular_theta_d),
  };
  m.make = make_deon2011;
  m.approximations = deon_approximations;
  m.from_fiber = deon2011_from_fiber;
  m.theta_r_shifts = [](const P& p) { return p.alpha; };
  return define_model(std::move(m));
}

}  // namespace fiberlab::analytic
