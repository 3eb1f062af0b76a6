#include "analytic/chiang2016.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "analytic/azimuthal_lobes.h"
#include "analytic/bin_integration.h"
#include "analytic/longitudinal_lobes.h"
#include "analytic/model_params.h"
#include "analytic/model_registry.h"
#include "analytic/pbrt_v4_mp.h"
#include "analytic/physical_defaults.h"
#include "analytic/quadrature.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "common/units.h"

namespace fiberlab::analytic {
namespace chiang2016 {

double longitudinal_variance(double beta_m) {
  const double x = 0.726 * beta_m + 0.812 * beta_m * beta_m + 3.7 * std::pow(beta_m, 20);
  return x * x;
}

double logistic_scale(double beta_n) {
  return std::sqrt(kPi / 8.0) *
         (0.265 * beta_n + 1.194 * beta_n * beta_n + 5.372 * std::pow(beta_n, 22));
}

namespace {
double invert_increasing(double (*f)(double), double y, const char* what) {
  if (!(y >= 0.0) || !(y <= f(1.0)))
    throw Error(fmt::format("chiang2016: {} = {} lies beyond beta = 1 (at most {})", what, y, f(1.0)));
  if (y == 0.0) return 0.0;  // f(0) = 0: the exact smooth limit
  double lo = 0.0, hi = 1.0;
  for (int it = 0; it < 100; ++it) {
    const double m = 0.5 * (lo + hi);
    if (f(m) < y) lo = m; else hi = m;
  }
  return 0.5 * (lo + hi);
}
double r_width(double beta_m) { return std::sqrt(longitudinal_variance(beta_m)); }
}  // namespace

double beta_m_for_width(double width) { return invert_increasing(r_width, width, "R lobe width"); }
double beta_n_for_scale(double s) { return invert_increasing(logistic_scale, s, "logistic scale"); }

}  // namespace chiang2016

namespace {

constexpr double kDeltaV = 1e-10;        // v below this: M_p is a delta
constexpr double kSmoothS = 1e-12;       // s below this: the logistic is a delta
constexpr double kDensityMinV = 1e-8;    // density(): floor of v
constexpr double kDensityMinS = 1e-6;    // density(): floor of s
constexpr double kWindow = 12.0;         // M_p cos beyond 12 sqrt(v): < e^-70
constexpr int kOrder = 8;                // Gauss-Legendre points per panel
constexpr int kResidualP = 3;            // p_max: orders >= 3 in one residual lobe

// A quadrature node over h: gamma_i, weight of (1/2) int dh (includes
// cos(gamma_i) / 2) and the exit azimuth Phi(p, gamma_i) (unwrapped).
struct HNode {
  double gamma, weight, phi;
};

// gamma in [a, b] with Phi(p, gamma) = target, Phi monotonic on [a, b] and
// target between Phi(a) and Phi(b): bisection to rounding.
double gamma_at_phi(int p, double eta_p, double target, double a, double b) {
  const bool increasing = cylinder::Phi(p, b, eta_p) > cylinder::Phi(p, a, eta_p);
  for (int it = 0; it < 200 && b - a > 1e-16; ++it) {
    const double m = 0.5 * (a + b);
    if ((cylinder::Phi(p, m, eta_p) < target) == increasing) a = m; else b = m;
  }
  return 0.5 * (a + b);
}

// Composite Gauss-Legendre nodes on [a, b] with panels of at most max_len.
void add_panels(int p, double eta_p, double a, double b, double max_len, std::vector<HNode>& out) {
  if (!(b > a)) return;
  const GaussLegendre& gl = gauss_legendre(kOrder);
  const int m = std::max(1, static_cast<int>(std::ceil((b - a) / max_len)));
  const double half = 0.5 * (b - a) / m;
  for (int k = 0; k < m; ++k) {
    const double mid = a + (2 * k + 1) * half;
    for (int q = 0; q < kOrder; ++q) {
      const double g = mid + half * gl.x[q];
      out.push_back({g, 0.5 * half * gl.w[q] * std::cos(g), cylinder::Phi(p, g, eta_p)});
    }
  }
}

// The monotonic pieces of Phi(p, .) on [-pi/2, pi/2] (split at the fold).
std::vector<double> branches(int p, double eta_p) {
  const double gc = cylinder::fold_gamma(p, eta_p);
  if (gc > 0.0 && gc < kPi / 2) return {-kPi / 2, -gc, gc, kPi / 2};
  return {-kPi / 2, kPi / 2};
}

// Nodes over h for N_p with logistic scale s > 0, resolving the logistic
// wherever Phi(p, h) lies within 40 s of one of `centres` (mod 2 pi): there
// Phi moves by at most 2 s per panel; elsewhere panels of pi/64 (or none,
// with skip_far: the logistic is below e^-40 of its peak there).
void logistic_nodes(int p, double eta_p, double s, const std::vector<double>& centres,
                    bool skip_far, double refine, std::vector<HNode>& out) {
  out.clear();
  const double W = azimuthal::kLogisticWindow * s;
  // max |dPhi/dgamma| over gamma: from 2p/eta' - 2 (gamma = 0) to -2 (|gamma| -> pi/2).
  const double slope = std::max(2.0, std::abs(2.0 * p / eta_p - 2.0));
  const double fine_len = std::min(kPi / 64, 2.0 * s / slope) / refine;
  const double coarse_len = kPi / 64 / refine;
  const std::vector<double> br = branches(p, eta_p);
  for (std::size_t k = 0; k + 1 < br.size(); ++k) {
    const double a = br[k], b = br[k + 1];
    const double pa = cylinder::Phi(p, a, eta_p), pb = cylinder::Phi(p, b, eta_p);
    const double lo = std::min(pa, pb), hi = std::max(pa, pb);
    // Fine intervals in Phi, merged.
    std::vector<std::pair<double, double>> fine;
    for (double c : centres) {
      const long k0 = static_cast<long>(std::ceil((lo - W - c) / kTwoPi));
      const long k1 = static_cast<long>(std::floor((hi + W - c) / kTwoPi));
      for (long m = k0; m <= k1; ++m) {
        const double x0 = std::max(lo, c + kTwoPi * m - W), x1 = std::min(hi, c + kTwoPi * m + W);
        if (x1 > x0) fine.emplace_back(x0, x1);
      }
    }
    std::sort(fine.begin(), fine.end());
    std::vector<std::pair<double, double>> merged;
    for (const auto& f : fine) {
      if (!merged.empty() && f.first <= merged.back().second)
        merged.back().second = std::max(merged.back().second, f.second);
      else
        merged.push_back(f);
    }
    // Segments of [lo, hi] in Phi order, each fine or far, mapped to gamma.
    auto to_gamma = [&](double x) {
      if (x <= lo) return pa < pb ? a : b;
      if (x >= hi) return pa < pb ? b : a;
      return gamma_at_phi(p, eta_p, x, a, b);
    };
    auto segment = [&](double x0, double x1, bool is_fine) {
      if (!(x1 > x0)) return;
      if (!is_fine && skip_far) return;
      double g0 = to_gamma(x0), g1 = to_gamma(x1);
      if (g0 > g1) std::swap(g0, g1);
      add_panels(p, eta_p, g0, g1, is_fine ? fine_len : coarse_len, out);
    };
    if (hi - lo <= 0.0) {  // constant Phi (not for p <= 3, kept for safety)
      add_panels(p, eta_p, a, b, coarse_len, out);
      continue;
    }
    double x = lo;
    for (const auto& f : merged) {
      segment(x, f.first, false);
      segment(f.first, f.second, true);
      x = f.second;
    }
    segment(x, hi, false);
  }
}

// Nodes over h for smooth integrands (energies): pi/64 panels.
void plain_nodes(int p, double eta_p, std::vector<HNode>& out) {
  out.clear();
  const std::vector<double> br = branches(p, eta_p);
  for (std::size_t k = 0; k + 1 < br.size(); ++k) add_panels(p, eta_p, br[k], br[k + 1], kPi / 64, out);
}

// (1/2) int A_p dh per channel; p = 3 is the residual sum over p >= 3 (A_3
// in closed form). The integrands are smooth in gamma_i: pi/64 panels.
void order_energy(const cylinder::Attenuation& att, int p, std::vector<double>& out) {
  const int C = att.channels();
  out.assign(C, 0.0);
  std::vector<double> a(C);
  std::vector<HNode> nodes;
  plain_nodes(0, att.eta_p(), nodes);
  for (const HNode& nd : nodes) {
    if (p < kResidualP) att.A(p, nd.gamma, a.data());
    else att.A_beyond(kResidualP - 1, nd.gamma, a.data());
    for (int c = 0; c < C; ++c) out[c] += nd.weight * a[c];
  }
}

// log M_p: d'Eon 2011 Eq. 7 (the paper's) or pbrt-v4's as shipped (pbrt_v4_mp.h).
double log_mp(bool pbrt, double v, double theta_i, double theta_r) {
  return pbrt ? pbrt_v4::log_M_p(v, theta_i, theta_r) : longitudinal::vmf_log_M_p(v, theta_i, theta_r);
}

// Integral of M_p(v, theta_eff, theta_r) cos(theta_r) over every theta bin,
// added to out[i]: Gauss-Legendre on panels below sqrt(v)/3 within
// kWindow sqrt(v) of the peak.

void theta_bin_integrals(bool pbrt, double v, double theta_eff, const BinGrid& grid, double refine,
                         std::vector<double>& out) {
  const double peak = -theta_eff;
  if (v < kDeltaV) {
    // M_p -> delta(theta_r + theta_eff) / cos(theta_eff): unit mass at the peak.
    out[grid.theta_bin(peak)] += 1.0;
    return;
  }
  const double sv = std::sqrt(v);
  const double lo = std::max(-kPi / 2, peak - kWindow * sv), hi = std::min(kPi / 2, peak + kWindow * sv);
  const double max_len = std::min(sv / 3.0, 0.05) / refine;
  add_theta_bin_integrals(
      grid.theta_edges, lo, hi, max_len,
      [&](double tr, double w) { return w * std::exp(log_mp(pbrt, v, theta_eff, tr)) * std::cos(tr); }, out);
}

}  // namespace

Chiang2016::Chiang2016(Chiang2016Params params) : params_(std::move(params)) {
  auto bad = [](const std::string& what) { throw Error("chiang2016: " + what); };
  const Chiang2016Params& p = params_;
  if (!(p.eta > 1.0) || !std::isfinite(p.eta)) bad(fmt::format("eta = {} must be > 1", p.eta));
  if (!(p.beta_m >= 0.0 && p.beta_m <= 1.0)) bad(fmt::format("beta_m = {} must be in [0, 1]", p.beta_m));
  if (!(p.beta_n >= 0.0 && p.beta_n <= 1.0)) bad(fmt::format("beta_n = {} must be in [0, 1]", p.beta_n));
  if (!(std::abs(p.alpha) < kPi / 4))
    bad(fmt::format("alpha = {:g} deg must be in (-45, 45) degrees", rad_to_deg(p.alpha)));
  if (p.lobes < 1 || p.lobes > 4)
    bad(fmt::format("lobes = {} must be 1..4 (every order p >= 3 is one residual lobe)", p.lobes));
  if (p.sigma_a.empty()) bad("sigma_a needs at least one channel");
  for (double s : p.sigma_a)
    if (!(s >= 0.0) || !std::isfinite(s)) bad(fmt::format("sigma_a = {} must be finite and >= 0", s));
  v_ = chiang2016::longitudinal_variance(p.beta_m);
  s_ = chiang2016::logistic_scale(p.beta_n);
}

double Chiang2016::variance(int p) const {
  if (p == 0) return v_;
  if (p == 1) return 0.25 * v_;
  return 4.0 * v_;  // TRT and the residual
}

double Chiang2016::rotated_theta_i(int p, double theta_i) const {
  // Tilt shifts 2^k alpha (see the header for the sign); the residual is not rotated.
  static constexpr double kShift[4] = {2.0, -1.0, -4.0, 0.0};
  const double t = theta_i + kShift[std::min(p, 3)] * params_.alpha;
  // Past the pole the direction continues on the other side: sin kept, |cos|.
  return std::atan2(std::sin(t), std::abs(std::cos(t)));
}

void Chiang2016::density(int lobe, double theta_i, double, double theta_r, double phi,
                         std::vector<double>& out) const {
  const int C = static_cast<int>(params_.sigma_a.size()), L = params_.lobes;
  out.assign(C, 0.0);
  const cylinder::Attenuation att(params_.eta, theta_i, params_.sigma_a, Absorption::Chord);
  const double s = std::max(s_, kDensityMinS);
  std::vector<HNode> nodes;
  std::vector<double> a(C), n(C);
  for (int p = 0; p <= kResidualP; ++p) {
    if (lobe_of(p, L) != lobe) continue;
    const double v = std::max(variance(p), kDensityMinV);
    const double m =
        std::exp(log_mp(params_.mp == Chiang2016Mp::PbrtV4, v, rotated_theta_i(p, theta_i), theta_r)) * std::cos(theta_r);
    std::fill(n.begin(), n.end(), 0.0);
    if (p < kResidualP) {
      logistic_nodes(p, att.eta_p(), s, {phi}, true, 1.0, nodes);
      for (const HNode& nd : nodes) {
        att.A(p, nd.gamma, a.data());
        const double l = azimuthal::trimmed_logistic(wrap_angle(phi - nd.phi), s);
        for (int c = 0; c < C; ++c) n[c] += nd.weight * a[c] * l;
      }
    } else {
      order_energy(att, p, a);
      for (int c = 0; c < C; ++c) n[c] = a[c] / kTwoPi;
    }
    for (int c = 0; c < C; ++c) out[c] += m * n[c];
  }
}

std::vector<double> Chiang2016::lobe_energies(double theta_i) const {
  const int C = static_cast<int>(params_.sigma_a.size()), L = params_.lobes;
  std::vector<double> e(static_cast<std::size_t>(L) * C, 0.0), ep;
  const cylinder::Attenuation att(params_.eta, theta_i, params_.sigma_a, Absorption::Chord);
  for (int p = 0; p <= kResidualP; ++p) {
    order_energy(att, p, ep);
    for (int c = 0; c < C; ++c) e[static_cast<std::size_t>(lobe_of(p, L)) * C + c] += ep[c];
  }
  return e;
}

std::vector<double> Chiang2016::bin_probabilities(const BinGrid& grid, double theta_i,
                                                  double) const {
  const int nt = grid.n_theta(), np = grid.n_phi(), L = params_.lobes;
  const int C = static_cast<int>(params_.sigma_a.size());
  std::vector<double> out(static_cast<std::size_t>(L) * nt * np * C, 0.0);
  const cylinder::Attenuation att(params_.eta, theta_i, params_.sigma_a, Absorption::Chord);
  const double delta = kTwoPi / np;
  std::vector<double> edges(np + 1);
  for (int j = 0; j <= np; ++j) edges[j] = -kPi + j * delta;

  std::vector<double> a(C), theta_w, phi_w;
  std::vector<HNode> nodes;
  for (int p = 0; p <= kResidualP; ++p) {
    theta_w.assign(nt, 0.0);
    theta_bin_integrals(params_.mp == Chiang2016Mp::PbrtV4, variance(p), rotated_theta_i(p, theta_i), grid, refine_, theta_w);
    phi_w.assign(static_cast<std::size_t>(np) * C, 0.0);
    if (p == kResidualP) {
      // The residual is uniform in phi: E_3 / n_phi per bin.
      order_energy(att, p, a);
      for (int j = 0; j < np; ++j)
        for (int c = 0; c < C; ++c) phi_w[static_cast<std::size_t>(j) * C + c] = a[c] / np;
    } else if (s_ < kSmoothS) {
      // Delta detector: the smooth cylinder's nodes, split at the bin edges.
      cylinder::add_smooth_lobe(att, p, np, phi_w);
    } else {
      logistic_nodes(p, att.eta_p(), s_, edges, false, refine_, nodes);
      const double s = s_;
      auto cdf = [s](double x) { return azimuthal::trimmed_logistic_cumulative(x, s); };
      for (const HNode& nd : nodes) {
        att.A(p, nd.gamma, a.data());
        for (int c = 0; c < C; ++c) a[c] *= nd.weight;
        deposit_wrapped(cdf, nd.phi, s_, azimuthal::kLogisticWindow, true, a.data(), C, np, phi_w);
      }
    }
    double* lobe_out = &out[static_cast<std::size_t>(lobe_of(p, L)) * nt * np * C];
    for (int i = 0; i < nt; ++i) {
      if (theta_w[i] == 0.0) continue;
      double* row = &lobe_out[static_cast<std::size_t>(i) * np * C];
      for (std::size_t x = 0; x < phi_w.size(); ++x) row[x] += theta_w[i] * phi_w[x];
    }
  }
  return out;
}

std::unique_ptr<Model> make_chiang2016(const Chiang2016Params& params) {
  return std::make_unique<Chiang2016>(params);
}

namespace {

std::vector<std::string> chiang_approximations(const Chiang2016Params& p) {
  return {"far field: pbrt's BCSDF averaged over h, with pbrt's wo read as our wi (A_p at theta_i)",
          p.mp == Chiang2016Mp::PbrtV4
              ? "M_p: pbrt-v4's as shipped (10-term I0, its log I0 above 12, csch(1/v) ~ 2 exp(-1/v) for v <= 0.1); "
                "tilt as rotations of theta_i by 2 alpha, -alpha, -4 alpha"
              : "M_p: d'Eon's von Mises-Fisher lobe; tilt as rotations of theta_i by 2 alpha, -alpha, -4 alpha",
          "N_p: trimmed logistic about Phi(p, h) (not a physical detector)",
          "every order p >= 3 in one lobe, uniform in phi (p_max = 3)",
          "absorption: the chord (SPEC s7)"};
}

// The rule from a simulated fiber (physical_defaults.h): circular fibers
// only; the tilt itself; the widths as for d'Eon's M_p (the same function),
// then through the inverse mappings: an approximate width match; smooth
// gives 0 exactly.
void chiang2016_from_fiber(const PhysicalFiber& f, Chiang2016Params& p, FiberMapping& mapping) {
  if (f.eccentricity != 1.0)
    throw Error(fmt::format("model chiang2016: circular fibers only; this fiber has eccentricity {:g}",
                            f.eccentricity));
  apply_fiber_basics(f, p);
  p.alpha = f.scale_tilt;
  LobeWidths w;
  apply_fiber_roughness(f, w, deon2011_width_calibration(), mapping);
  p.beta_m = chiang2016::beta_m_for_width(for_lobe(w.beta_long, 0));
  p.beta_n = chiang2016::beta_n_for_scale(for_lobe(w.beta_azim, 0) * std::sqrt(3.0) / kPi);
}

}  // namespace

ModelInfo chiang2016_info() {
  using P = Chiang2016Params;
  ModelDefinition<P> m;
  m.name = "chiang2016";
  m.reference =
      "Chiang, Bitterli, Tappan, Burley 2016, A Practical and Controllable Hair and Fur Model for "
      "Production Path Tracing (pbrt-v4 HairBxDF), far field";
  auto unit_interval = [](double x) { return x >= 0.0 && x <= 1.0; };
  ParamSpec beta_m = number_param("beta_m", "longitudinal roughness: v = (0.726 b + 0.812 b^2 + 3.7 b^20)^2 (R; TT v/4, TRT 4v)",
                                  "", "0.3", "a number in [0, 1]", &P::beta_m, unit_interval);
  beta_m.from_fiber = "roughness: R's sqrt(v) = the R lobe's calibrated theta_r width";
  ParamSpec beta_n = number_param("beta_n", "azimuthal roughness: logistic s = sqrt(pi/8)(0.265 b + 1.194 b^2 + 5.372 b^22)",
                                  "", "0.3", "a number in [0, 1]", &P::beta_n, unit_interval);
  beta_n.from_fiber = "roughness: s pi / sqrt(3) = the R lobe's azimuthal width";
  ParamSpec alpha = number_param("alpha",
                                 "cuticle scale tilt, > 0 towards the root (R at theta_r = -theta_i - 2 alpha); "
                                 "pbrt-v4's alpha is its negative",
                                 "deg", "2", "degrees in (-45, 45)", &P::alpha,
                                 [](double x) { return std::abs(x) < 45.0; });
  alpha.from_fiber = "fiber.scale_tilt";
  // Free parameters (what `fiberlab atlas` fits), in the table's ranges.
  m.params = {eta_param<P>(),
              sigma_a_param<P>(),
              fittable(beta_m, 0.0, 1.0),
              fittable(beta_n, 0.0, 1.0),
              fittable(alpha, -45.0 + 1e-6, 45.0 - 1e-6),
              enum_param("mp",
                         "longitudinal function M_p: exact (d'Eon 2011 Eq. 7, the paper's) or pbrt_v4 (pbrt-v4's "
                         "HairBxDF numerics as shipped: 10-term I0, its asymptotic log I0 above 12)",
                         "exact", {"exact", "pbrt_v4"}, &P::mp),
              lobes_param<P>()};
  m.make = [](const P& p) { return make_chiang2016(p); };
  m.approximations = chiang_approximations;
  m.from_fiber = chiang2016_from_fiber;
  // The lobes' centres move as SPEC s7's shifts of the tilt (chiang2016.h).
  m.theta_r_shifts = [](const P& p) { return tilt_shifts(p.alpha); };
  return define_model(std::move(m));
}

}  // namespace fiberlab::analytic
