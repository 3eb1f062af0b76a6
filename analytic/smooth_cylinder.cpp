#include "analytic/smooth_cylinder.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "analytic/model_registry.h"
#include "analytic/quadrature.h"
#include "common/error.h"
#include "common/fresnel.h"
#include "common/units.h"

namespace fiberlab::analytic {
namespace cylinder {

double eta_prime(double eta, double theta) {
  const double s = std::sin(theta);
  const double c = std::max(std::cos(theta), 1e-300);
  return std::sqrt(eta * eta - s * s) / c;
}

double Phi(int p, double gamma_i, double eta_p) {
  const double gamma_t = std::asin(std::clamp(std::sin(gamma_i) / eta_p, -1.0, 1.0));
  return 2.0 * p * gamma_t - 2.0 * gamma_i + p * kPi;
}

double dPhi_dgamma(int p, double gamma_i, double eta_p) {
  const double s = std::sin(gamma_i) / eta_p;
  const double cos_t = std::sqrt(std::max(0.0, 1.0 - s * s));
  return 2.0 * p * std::cos(gamma_i) / (eta_p * cos_t) - 2.0;
}

double fold_gamma(int p, double eta_p) {
  if (p < 2 || eta_p >= p) return -1.0;
  const double s2 = (p * p - eta_p * eta_p) / (p * p - 1.0);
  return std::asin(std::sqrt(std::clamp(s2, 0.0, 1.0)));
}

Attenuation::Attenuation(double eta, double theta, const std::vector<double>& sigma_a,
                         Absorption absorption)
    : eta_(eta), cos_theta_(std::cos(theta)), eta_p_(eta_prime(eta, theta)),
      absorption_(absorption) {
  const double sin_t = std::sin(theta) / eta;
  const double cos_theta_t = std::sqrt(std::max(0.0, 1.0 - sin_t * sin_t));
  for (double s : sigma_a) sigma_a_prime_.push_back(s / cos_theta_t);
}

double Attenuation::f(double gamma_i) const {
  return fresnel_dielectric(std::clamp(cos_theta_ * std::cos(gamma_i), 0.0, 1.0), eta_);
}

void Attenuation::T(double gamma_i, double* out) const {
  const double s = std::sin(gamma_i) / eta_p_;
  const double cos2_t = std::max(0.0, 1.0 - s * s);
  // Chord: 2 cos(gamma_t); published: 2 (1 + cos 2 gamma_t) = 4 cos^2(gamma_t).
  const double length = absorption_ == Absorption::Chord ? 2.0 * std::sqrt(cos2_t) : 4.0 * cos2_t;
  for (std::size_t c = 0; c < sigma_a_prime_.size(); ++c)
    out[c] = std::exp(-sigma_a_prime_[c] * length);
}

void Attenuation::A(int p, double gamma_i, double* out) const {
  const double fr = f(gamma_i);
  const int C = channels();
  if (p == 0) {
    for (int c = 0; c < C; ++c) out[c] = fr;
    return;
  }
  T(gamma_i, out);
  const double base = (1.0 - fr) * (1.0 - fr) * std::pow(fr, p - 1);
  for (int c = 0; c < C; ++c) out[c] = base * std::pow(out[c], p);
}

void Attenuation::A_beyond(int P, double gamma_i, double* out) const {
  const double fr = f(gamma_i);
  T(gamma_i, out);
  const double base = (1.0 - fr) * (1.0 - fr) * std::pow(fr, P);
  for (int c = 0; c < channels(); ++c) {
    const double denom = 1.0 - fr * out[c];
    // f T -> 1 only when f -> 1, where (1 - f)^2 / (1 - f T) -> 0.
    out[c] = denom > 1e-300 ? base * std::pow(out[c], P + 1) / denom : 0.0;
  }
}

int phi_bin(double phi, int n_phi) {
  const int j = static_cast<int>(std::floor((phi + kPi) / kTwoPi * n_phi));
  return std::clamp(j, 0, n_phi - 1);
}

namespace {

// The monotonic pieces of Phi(p, .) on [-pi/2, pi/2].
std::vector<double> monotonic_breaks(int p, double eta_p) {
  const double gc = fold_gamma(p, eta_p);
  if (gc > 0.0 && gc < kPi / 2) return {-kPi / 2, -gc, gc, kPi / 2};
  return {-kPi / 2, kPi / 2};
}

// gamma in [a, b] with Phi(gamma) = e, Phi monotonic on [a, b] and e strictly
// between Phi(a) and Phi(b): Newton safeguarded by bisection.
double solve_phi(int p, double eta_p, double e, double a, double b, double phi_a, double phi_b) {
  const bool increasing = phi_b > phi_a;
  double lo = a, hi = b;
  double x = a + (b - a) * (e - phi_a) / (phi_b - phi_a);
  for (int it = 0; it < 200; ++it) {
    const double g = Phi(p, x, eta_p) - e;
    if (g == 0.0) return x;
    if ((g < 0.0) == increasing) lo = x; else hi = x;
    const double d = dPhi_dgamma(p, x, eta_p);
    double xn = x - g / d;
    if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
    if (std::abs(xn - x) <= 1e-16 * (1.0 + std::abs(x)) || hi - lo <= 1e-16) return xn;
    x = xn;
  }
  return x;
}

void add_piece_nodes(int p, double eta_p, double a, double b, int order, double max_len,
                     std::vector<PathNode>& out) {
  if (!(b > a)) return;
  const int m = std::max(1, static_cast<int>(std::ceil((b - a) / max_len)));
  const double len = (b - a) / m;
  // Short pieces (high orders p cross a bin edge every few 1e-3 rad of
  // gamma) carry an integrand that is a low-degree polynomial to rounding
  // over their length: fewer points there (error ~ len^(2n), len < 0.005).
  if (len < 0.005) order = std::min(order, 3);
  const GaussLegendre& gl = gauss_legendre(order);
  for (int k = 0; k < m; ++k) {
    const double c0 = a + k * len;
    const double half = 0.5 * len, mid = c0 + half;
    for (int q = 0; q < order; ++q) {
      const double g = mid + half * gl.x[q];
      out.push_back({g, 0.5 * half * gl.w[q] * std::cos(g), wrap_angle(Phi(p, g, eta_p))});
    }
  }
}

}  // namespace

void smooth_nodes(int p, double eta_p, int n_phi, int order, std::vector<PathNode>& out) {
  out.clear();
  const double delta = kTwoPi / n_phi;
  const std::vector<double> br = monotonic_breaks(p, eta_p);
  std::vector<double> cuts;
  for (std::size_t k = 0; k + 1 < br.size(); ++k) {
    const double a = br[k], b = br[k + 1];
    const double pa = Phi(p, a, eta_p), pb = Phi(p, b, eta_p);
    const double lo = std::min(pa, pb), hi = std::max(pa, pb);
    cuts.assign(1, a);
    const long m0 = static_cast<long>(std::ceil((lo + kPi) / delta));
    const long m1 = static_cast<long>(std::floor((hi + kPi) / delta));
    for (long m = m0; m <= m1; ++m) {
      const double e = -kPi + m * delta;
      if (e <= lo || e >= hi) continue;
      cuts.push_back(solve_phi(p, eta_p, e, a, b, pa, pb));
    }
    cuts.push_back(b);
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t c = 0; c + 1 < cuts.size(); ++c)
      add_piece_nodes(p, eta_p, cuts[c], cuts[c + 1], order, kPi / 64, out);
  }
}

void panel_nodes(int p, double eta_p, double max_dphi, int order, std::vector<PathNode>& out) {
  out.clear();
  const std::vector<double> br = monotonic_breaks(p, eta_p);
  for (std::size_t k = 0; k + 1 < br.size(); ++k) {
    const double a = br[k], b = br[k + 1];
    double slope = std::max(std::abs(dPhi_dgamma(p, a, eta_p)), std::abs(dPhi_dgamma(p, b, eta_p)));
    if (a < 0.0 && b > 0.0) slope = std::max(slope, std::abs(dPhi_dgamma(p, 0.0, eta_p)));
    const double max_len = std::min(kPi / 16, max_dphi / std::max(slope, 1e-12));
    add_piece_nodes(p, eta_p, a, b, order, max_len, out);
  }
}

}  // namespace cylinder

SmoothCylinderPrediction smooth_cylinder_prediction(double eta, double theta_i,
                                                    const std::vector<double>& sigma_a,
                                                    Absorption absorption, int lobes, int n_phi,
                                                    double residual_tol, int max_p) {
  if (lobes < 1 || n_phi < 1 || sigma_a.empty())
    throw Error("smooth_cylinder_prediction: lobes, n_phi and channels must be >= 1");
  SmoothCylinderPrediction r;
  r.lobes = lobes;
  r.n_phi = n_phi;
  const int C = static_cast<int>(sigma_a.size());
  r.channels = C;
  r.energy.assign(static_cast<std::size_t>(lobes) * C, 0.0);
  r.phi_bins.assign(static_cast<std::size_t>(lobes) * n_phi * C, 0.0);
  const cylinder::Attenuation att(eta, theta_i, sigma_a, absorption);
  std::vector<cylinder::PathNode> nodes;
  std::vector<double> a(C), res_e(C);
  for (int p = 0;; ++p) {
    const int lobe = lobe_of(p, lobes);
    cylinder::smooth_nodes(p, att.eta_p(), n_phi, 6, nodes);
    std::fill(res_e.begin(), res_e.end(), 0.0);
    const bool last = p >= lobes - 1;
    for (const auto& nd : nodes) {
      att.A(p, nd.gamma, a.data());
      const int j = cylinder::phi_bin(nd.phi, n_phi);
      double* bin = &r.phi_bins[(static_cast<std::size_t>(lobe) * n_phi + j) * C];
      for (int c = 0; c < C; ++c) {
        bin[c] += nd.weight * a[c];
        r.energy[lobe * C + c] += nd.weight * a[c];
      }
      if (last) {
        att.A_beyond(p, nd.gamma, a.data());
        for (int c = 0; c < C; ++c) res_e[c] += nd.weight * a[c];
      }
    }
    if (!last) continue;
    const double worst = *std::max_element(res_e.begin(), res_e.end());
    if (worst <= residual_tol || p >= max_p) {
      r.max_explicit_p = p;
      r.residual_energy = worst;
      for (int c = 0; c < C; ++c) {
        r.energy[lobe * C + c] += res_e[c];
        for (int j = 0; j < n_phi; ++j)
          r.phi_bins[(static_cast<std::size_t>(lobe) * n_phi + j) * C + c] += res_e[c] / n_phi;
      }
      break;
    }
  }
  return r;
}

SmoothCylinder::SmoothCylinder(ModelParams params) : params_(std::move(params)) {
  if (!(params_.eta > 1.0)) throw Error(fmt::format("exact model: eta = {} must be > 1", params_.eta));
  if (params_.eccentricity != 1.0)
    throw Error(fmt::format("exact model: eccentricity = {} unsupported (circular fiber only, 1)",
                            params_.eccentricity));
  if (params_.lobes < 1) throw Error("exact model: lobes must be >= 1");
  if (params_.sigma_a.empty()) throw Error("exact model: sigma_a needs at least one channel");
}

void SmoothCylinder::density(int lobe, double theta_i, double, double theta_r, double phi,
                             std::vector<double>& out) const {
  const int C = static_cast<int>(params_.sigma_a.size());
  out.assign(C, 0.0);
  if (std::abs(theta_r + theta_i) > 1e-9) return;
  const cylinder::Attenuation att(params_.eta, theta_i, params_.sigma_a, params_.absorption);
  const double eta_p = att.eta_p();
  std::vector<double> a(C);
  const int L = params_.lobes;
  const int p_first = lobe, p_last_fixed = lobe < L - 1 ? lobe : -1;
  // Orders of the last lobe: up to the point where the remaining energy is
  // negligible (64-point estimate), the remainder spread uniformly in phi.
  int p_end = p_last_fixed;
  double res_sum[16] = {0};
  if (p_end < 0) {
    const GaussLegendre& gl = gauss_legendre(64);
    for (int P = lobe;; ++P) {
      double worst = 0.0;
      std::vector<double> acc(C, 0.0);
      for (int q = 0; q < 64; ++q) {
        const double g = 0.5 * kPi * gl.x[q];
        att.A_beyond(P, g, a.data());
        for (int c = 0; c < C; ++c) acc[c] += 0.25 * kPi * gl.w[q] * std::cos(g) * a[c];
      }
      for (int c = 0; c < C; ++c) worst = std::max(worst, acc[c]);
      if (worst <= 1e-7 || P >= 100) {
        p_end = P;
        for (int c = 0; c < C && c < 16; ++c) res_sum[c] = acc[c];
        break;
      }
    }
  }
  for (int p = p_first; p <= p_end; ++p) {
    const std::vector<double> br = [&] {
      const double gc = cylinder::fold_gamma(p, eta_p);
      if (gc > 0.0) return std::vector<double>{-kPi / 2, -gc, gc, kPi / 2};
      return std::vector<double>{-kPi / 2, kPi / 2};
    }();
    for (std::size_t k = 0; k + 1 < br.size(); ++k) {
      const double ga = br[k], gb = br[k + 1];
      const double pa = cylinder::Phi(p, ga, eta_p), pb = cylinder::Phi(p, gb, eta_p);
      const double lo = std::min(pa, pb), hi = std::max(pa, pb);
      for (long m = static_cast<long>(std::ceil((lo - phi) / kTwoPi));
           phi + m * kTwoPi <= hi; ++m) {
        const double e = phi + m * kTwoPi;
        if (e <= lo || e >= hi) continue;
        // Bisection on the monotonic piece (density() is not performance critical).
        double x0 = ga, x1 = gb;
        const bool inc = pb > pa;
        for (int it = 0; it < 200 && x1 - x0 > 1e-15; ++it) {
          const double xm = 0.5 * (x0 + x1);
          if ((cylinder::Phi(p, xm, eta_p) < e) == inc) x0 = xm; else x1 = xm;
        }
        const double g = 0.5 * (x0 + x1);
        att.A(p, g, a.data());
        const double jac = std::cos(g) / (2.0 * std::abs(cylinder::dPhi_dgamma(p, g, eta_p)));
        for (int c = 0; c < C; ++c) out[c] += a[c] * jac;
      }
    }
  }
  if (p_last_fixed < 0)
    for (int c = 0; c < C && c < 16; ++c) out[c] += res_sum[c] / kTwoPi;
}

std::vector<double> SmoothCylinder::bin_probabilities(const BinGrid& grid, double theta_i,
                                                      double) const {
  const int nt = grid.n_theta(), np = grid.n_phi(), L = params_.lobes;
  const int C = static_cast<int>(params_.sigma_a.size());
  std::vector<double> out(static_cast<std::size_t>(L) * nt * np * C, 0.0);
  const SmoothCylinderPrediction pr =
      smooth_cylinder_prediction(params_.eta, theta_i, params_.sigma_a, params_.absorption, L, np);
  const int i = grid.theta_bin(-theta_i);
  for (int l = 0; l < L; ++l)
    for (int j = 0; j < np; ++j)
      for (int c = 0; c < C; ++c)
        out[((static_cast<std::size_t>(l) * nt + i) * np + j) * C + c] =
            pr.phi_bins[(static_cast<std::size_t>(l) * np + j) * C + c];
  return out;
}

std::unique_ptr<Model> make_smooth_cylinder(const ModelParams& params) {
  return std::make_unique<SmoothCylinder>(params);
}

}  // namespace fiberlab::analytic

// ---- Parameter table and registry entry -------------------------------------------

namespace fiberlab::analytic {

namespace {
std::vector<std::string> exact_approximations(const ModelParams& p) {
  std::vector<std::string> out{
      "smooth circular fiber, no tilt: light only on the specular cone theta_r = -theta_i"};
  if (p.absorption == Absorption::Published)
    out.push_back("absorption=published: exp(-4 sigma_a' cos^2 gamma_t), not the chord 2 cos gamma_t "
                  "(the exact model is then not exact)");
  else
    out.push_back("absorption=chord: the exact chord length (SPEC s7)");
  return out;
}
}  // namespace

ModelInfo exact_info() {
  ModelInfo m;
  m.name = "exact";
  m.reference = "the exact smooth circular cylinder (SPEC s7): every order p, 3D Fresnel, chord absorption";
  m.params = {eta_param(), sigma_a_param(), absorption_param("chord"), lobes_param()};
  m.make = make_smooth_cylinder;
  m.approximations = exact_approximations;
  m.from_fiber = [](const PhysicalFiber& f, ModelParams& p) {
    if (f.eccentricity != 1.0)
      throw Error(fmt::format("model exact: circular fibers only; this fiber has eccentricity {:g}",
                              f.eccentricity));
    apply_fiber_basics(f, p);
    p.alpha = {0.0};  // no tilt in this model
  };
  return m;
}

}  // namespace fiberlab::analytic
