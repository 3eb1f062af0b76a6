#pragma once
// Microfacet normal distributions for the simulator's `roughness: {model:
// beckmann | ggx, alpha: A}` (sim/roughness/microfacet_roughness.h uses them):
// the distribution D of microfacet normals about a mean (possibly tilted)
// normal n, Smith's masking G1, and exact sampling of the distribution of
// visible normals (VNDF)
//
//   D_w(m) = G1(w) max(0, w.m) D(m) / (w.n),   integral over m = 1,
//
// for a direction w on the side n faces (w = -d for a photon travelling
// along d towards the boundary). Anisotropic: alpha_long is the roughness
// along the fiber axis projected onto the tangent plane of n, alpha_azim
// along n x that axis (the azimuthal direction about the fiber).
//
// In the local frame (x longitudinal, y azimuthal, z = n), with
// r^2 = m_x^2 / alpha_long^2 + m_y^2 / alpha_azim^2:
//   GGX:      D(m) = 1 / (pi a_l a_a (r^2 + m_z^2)^2)
//   Beckmann: D(m) = exp(-r^2 / m_z^2) / (pi a_l a_a m_z^4)
// both normalised as integral D(m) (m.n) dm = 1 over the hemisphere.
// Smith's Lambda, with a = w_z / sqrt(a_l^2 w_x^2 + a_a^2 w_y^2):
//   GGX:      Lambda = (-1 + sqrt(1 + 1/a^2)) / 2
//   Beckmann: Lambda = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi))
// and G1 = 1 / (1 + Lambda) (Heitz 2014, "Understanding the Masking-Shadowing
// Function in Microfacet-Based BRDFs", sections 5.1-5.3).
//
// Sampling (no rejection, no cap):
// - GGX: Heitz 2018, "Sampling the GGX Distribution of Visible Normals"
//   (JCGT 7(4)): stretch w to the alpha = 1 configuration, sample the
//   projected hemisphere disk warped towards w, unstretch.
// - Beckmann: Heitz and d'Eon 2014, "Importance Sampling Microfacet-Based
//   BSDFs using the Distribution of Visible Normals" (EGSR), section 4: in the
//   stretched configuration with w at inclination theta in the x-z plane the
//   visible slope density is (cos theta - x sin theta) exp(-x^2 - y^2) / pi
//   (x < cot theta): y is Normal(0, 1/2) given x, and x inverts the closed-form
//   marginal C(x) = cos theta (1 + erf x) / 2 + sin theta exp(-x^2) / (2 sqrt pi)
//   by safeguarded Newton iteration to rounding (exact, not a fit).
// Lambda, G1 and the samplers are sim/roughness/microfacet_lanes.h's, which
// the tracers run for one photon or a vector of photons; this class is their
// one-photon form in Eigen vectors, and adds D.
#include <optional>

#include "common/fiber_frame.h"
#include "sim/roughness/microfacet_lanes.h"

namespace fiberlab::sim {

// Orthonormal frame about a mean normal n: t along the fiber axis u = x
// projected onto n's tangent plane (longitudinal), b = n x t (azimuthal);
// life::MicrofacetFrameOf<double> in Eigen vectors.
struct MicrofacetFrame {
  Vec3 t, b, n;
  // n unit.
  static MicrofacetFrame about(const Vec3& n);
  Vec3 to_local(const Vec3& v) const { return Vec3(v.dot(t), v.dot(b), v.dot(n)); }
  Vec3 to_world(const Vec3& v) const { return v.x() * t + v.y() * b + v.z() * n; }
};

class MicrofacetDistribution {
 public:
  // alpha_long, alpha_azim > 0 (throws fiberlab::Error otherwise).
  MicrofacetDistribution(MicrofacetModel model, double alpha_long, double alpha_azim);
  MicrofacetModel model() const { return model_; }
  double alpha_long() const { return ax_; }
  double alpha_azim() const { return ay_; }

  // Everything below in the local frame (z = the mean normal), unit vectors.
  // D(m) per steradian of m; 0 for m_z <= 0.
  double D(const Vec3& m) const;
  // Smith's Lambda(w) and G1(w) = 1 / (1 + Lambda) for w_z > 0 (G1 = 0 for w_z <= 0).
  double Lambda(const Vec3& w) const;
  double G1(const Vec3& w) const;
  // The VNDF D_w(m) = G1(w) max(0, w.m) D(m) / w_z per steradian (0 for w_z <= 0).
  double visible_density(const Vec3& w, const Vec3& m) const;
  // A normal m distributed as D_w from two uniforms in [0, 1); w_z > 0.
  Vec3 sample_visible(const Vec3& w, double u1, double u2) const;

  // World-space convenience: the photon travels along d (d.n < 0). Returns
  // nothing when d does not hit the front of the mean normal (d.n >= 0: the
  // caller's fallback, SPEC s3); otherwise m with d.m < 0, in world space.
  std::optional<Vec3> sample_visible(const MicrofacetFrame& frame, const Vec3& d, double u1,
                                     double u2) const;

 private:
  MicrofacetModel model_;
  double ax_, ay_;
};

}  // namespace fiberlab::sim
