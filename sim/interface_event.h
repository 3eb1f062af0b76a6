#pragma once
// One interface event (SPEC section 3): given the photon's direction d, its
// side and a microfacet normal m (d.m < 0), choose reflection with the Fresnel
// probability or refraction by Snell's law.
//
// The polarisation state is a template parameter so that the tracer is the
// same for scalar and Stokes light: ScalarLight carries nothing and uses the
// unpolarised reflectance F = (Rs + Rp) / 2.
#include "common/fiber_frame.h"
#include "sim/random.h"

namespace fiberlab::sim {

struct EventResult {
  Vec3 direction;
  bool refracted;  // the photon changed side
};

// Mirror reflection of d about m.
inline Vec3 reflect(const Vec3& d, const Vec3& m, double cos_i) {
  return (d + 2.0 * cos_i * m).normalized();
}

// Vector Snell's law: eta_ratio = n_i / n_t, cos_t > 0 the refraction cosine.
inline Vec3 refract(const Vec3& d, const Vec3& m, double cos_i, double eta_ratio,
                    double cos_t) {
  return (eta_ratio * d + (eta_ratio * cos_i - cos_t) * m).normalized();
}

struct ScalarLight {
  static constexpr bool kPolarized = false;
  // d: direction, m: normal with d.m < 0, eta_rel = n_t / n_i.
  EventResult interact(const Vec3& d, const Vec3& m, double eta_rel, PhotonRandom& rng);
};

}  // namespace fiberlab::sim

namespace fiberlab::sim {

// `polarization: stokes` (SPEC section 3): the photon carries one Stokes
// vector (I, Q, U, V), kept at I = 1, referred to an axis e1 perpendicular to
// its direction. At each event the reference axis is first turned to the
// event's s-axis, then the photon reflects with probability (first row of the
// reflection Mueller matrix) . (I, Q, U, V) and the Stokes vector becomes the
// chosen Mueller matrix times itself, renormalised to I = 1.
class StokesLight {
 public:
  static constexpr bool kPolarized = true;
  // Unpolarised light travelling along d.
  explicit StokesLight(const Vec3& d);
  EventResult interact(const Vec3& d, const Vec3& m, double eta_rel, PhotonRandom& rng);

  const Eigen::Vector4d& stokes() const { return stokes_; }
  const Vec3& reference_axis() const { return e1_; }

 private:
  // Turn the reference axis about d to s; (Q, U) rotate by 2 psi.
  void rotate_reference(const Vec3& d, const Vec3& s);

  Eigen::Vector4d stokes_{1.0, 0.0, 0.0, 0.0};
  Vec3 e1_;
};

}  // namespace fiberlab::sim
