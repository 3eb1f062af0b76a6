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

SmoothCylinder::SmoothCylinder(ExactParams params) : params_(std::move(params)) {
  if (!(params_.eta > 1.0)) throw Error(fmt::format("exact model: eta = {} must be > 1", params_.eta));
  if (params_.lobes < 1) throw Error("exact model: lobes must be >= 1");
  if (params_.sigma_a.empty()) throw Error("exact model: sigma_a needs at least one channel");
}

namespace {
// N_p(phi) (SPEC s7): the sum over the roots gamma of Phi(p, gamma) = phi
// (mod 2 pi) of A(p, h) / |2 dPhi/dh|, dh = cos(gamma) dgamma, added to
// out[c]; the roots by bisection on the monotonic pieces of Phi.
void add_N_p(const cylinder::Attenuation& att, int p, double phi, std::vector<double>& out) {
  const int C = att.channels();
  const double eta_p = att.eta_p();
  std::vector<double> a(C);
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
}  // namespace

void SmoothCylinder::density(int lobe, double theta_i, double, double theta_r, double phi,
                             std::vector<double>& out) const {
  const int C = static_cast<int>(params_.sigma_a.size());
  out.assign(C, 0.0);
  if (std::abs(theta_r + theta_i) > 1e-9) return;
  const cylinder::Attenuation att(params_.eta, theta_i, params_.sigma_a, params_.absorption);
  const int L = params_.lobes;
  const int p_first = lobe, p_last_fixed = lobe < L - 1 ? lobe : -1;
  // Orders of the last lobe: up to the point where the remaining energy is
  // negligible, the remainder spread uniformly in phi.
  std::vector<double> res;
  const int p_end = p_last_fixed >= 0 ? p_last_fixed : cylinder::last_order(att, lobe, 1e-7, 100, res);
  for (int p = p_first; p <= p_end; ++p) add_N_p(att, p, phi, out);
  if (p_last_fixed < 0)
    for (int c = 0; c < C; ++c) out[c] += res[c] / kTwoPi;
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

std::unique_ptr<Model> make_smooth_cylinder(const ExactParams& params) {
  return std::make_unique<SmoothCylinder>(params);
}

}  // namespace fiberlab::analytic

// ---- Parameter table and registry entry -------------------------------------------

namespace fiberlab::analytic {

namespace {
std::vector<std::string> exact_approximations(const ExactParams& p) {
  std::vector<std::string> out{
      "smooth circular fiber, no tilt: light only on the specular cone theta_r = -theta_i"};
  if (p.absorption == Absorption::Published)
    out.push_back("absorption=published: exp(-4 sigma_a' cos^2 gamma_t), not the chord 2 cos gamma_t "
                  "(the exact model is then not exact)");
  else
    out.push_back("absorption=chord: the exact chord length (SPEC s7)");
  return out;
}
// The rule from a simulated fiber (physical_defaults.h): circular fibers
// only; no roughness and no tilt in this model.
void exact_from_fiber(const PhysicalFiber& f, ExactParams& p, FiberMapping&) {
  if (f.eccentricity != 1.0)
    throw Error(fmt::format("model exact: circular fibers only; this fiber has eccentricity {:g}",
                            f.eccentricity));
  apply_fiber_basics(f, p);
}

}  // namespace

ModelInfo exact_info() {
  using P = ExactParams;
  ModelDefinition<P> m;
  m.name = "exact";
  m.reference = "the exact smooth circular cylinder (SPEC s7): every order p, 3D Fresnel, chord absorption";
  m.params = {eta_param<P>(), sigma_a_param<P>(), absorption_param<P>("chord"), lobes_param<P>()};
  m.make = make_smooth_cylinder;
  m.approximations = exact_approximations;
  m.from_fiber = exact_from_fiber;
  m.theta_r_shifts = [](const P&) { return std::vector<double>{0.0}; };  // no tilt in this model
  return define_model(std::move(m));
}

}  // namespace fiberlab::analytic
