#include "sim/interface_event.h"

#include <algorithm>
#include <cmath>

#include "common/fresnel.h"

namespace fiberlab::sim {

EventResult ScalarLight::interact(const Vec3& d, const Vec3& m, double eta_rel,
                                  PhotonRandom& rng) {
  // F uses the true 3D angle between d and m (SPEC section 3).
  const double cos_i = std::clamp(-d.dot(m), 0.0, 1.0);
  const double eta_ratio = 1.0 / eta_rel;
  const double sin2_t = eta_ratio * eta_ratio * (1.0 - cos_i * cos_i);
  if (sin2_t >= 1.0) return {reflect(d, m, cos_i), false};  // total internal reflection
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double F = fresnel_dielectric(cos_i, eta_rel);
  if (rng.uniform() < F) return {reflect(d, m, cos_i), false};
  return {refract(d, m, cos_i, eta_ratio, cos_t), true};
}

}  // namespace fiberlab::sim

#include <complex>

namespace fiberlab::sim {

namespace {

using Complex = std::complex<double>;

// Mueller matrix of SPEC section 3 in the s/p frame:
// [[A, B, 0, 0], [B, A, 0, 0], [0, 0, C, S], [0, 0, -S, C]].
struct Mueller {
  double A, B, C, S;
  Eigen::Vector4d times(const Eigen::Vector4d& v) const {
    return {A * v[0] + B * v[1], B * v[0] + A * v[1], C * v[2] + S * v[3], -S * v[2] + C * v[3]};
  }
};

// Fresnel amplitudes with SPEC section 3's signs, eta_r = n_t / n_i:
// r_s = (cos i - eta_r cos t) / (cos i + eta_r cos t),
// r_p = (eta_r cos i - cos t) / (eta_r cos i + cos t),
// cos t = +i sqrt(sin^2 i / eta_r^2 - 1) under total internal reflection.
struct Amplitudes {
  Complex r_s, r_p;
  double cos_t;  // real refraction cosine; < 0 under TIR
};

Amplitudes amplitudes(double cos_i, double eta_r) {
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta_r * eta_r);
  Complex cos_t;
  double real_cos_t = -1.0;
  if (sin2_t >= 1.0) {
    cos_t = Complex(0.0, std::sqrt(sin2_t - 1.0));
  } else {
    real_cos_t = std::sqrt(1.0 - sin2_t);
    cos_t = real_cos_t;
  }
  const Complex r_s = (cos_i - eta_r * cos_t) / (cos_i + eta_r * cos_t);
  const Complex r_p = (eta_r * cos_i - cos_t) / (eta_r * cos_i + cos_t);
  return {r_s, r_p, real_cos_t};
}

Mueller reflection_matrix(const Amplitudes& a) {
  const double rs2 = std::norm(a.r_s), rp2 = std::norm(a.r_p);
  const Complex x = a.r_s * std::conj(a.r_p);
  return {0.5 * (rs2 + rp2), 0.5 * (rs2 - rp2), x.real(), x.imag()};
}

Mueller transmission_matrix(const Amplitudes& a) {
  const double Ts = 1.0 - std::norm(a.r_s), Tp = 1.0 - std::norm(a.r_p);
  return {0.5 * (Ts + Tp), 0.5 * (Ts - Tp), std::sqrt(std::max(0.0, Ts * Tp)), 0.0};
}

}  // namespace

StokesLight::StokesLight(const Vec3& d) {
  const Vec3 helper = std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  e1_ = d.cross(helper).normalized();
}

void StokesLight::rotate_reference(const Vec3& d, const Vec3& s) {
  // psi from e1 to s about d: cos psi = e1.s, sin psi = (d x e1).s.
  const double c = e1_.dot(s), sn = d.cross(e1_).dot(s);
  const double c2 = c * c - sn * sn, s2 = 2.0 * c * sn;  // cos 2 psi, sin 2 psi
  const double q = stokes_[1], u = stokes_[2];
  stokes_[1] = c2 * q + s2 * u;
  stokes_[2] = -s2 * q + c2 * u;
  e1_ = s;
}

EventResult StokesLight::interact(const Vec3& d, const Vec3& m, double eta_rel,
                                  PhotonRandom& rng) {
  const double cos_i = std::clamp(-d.dot(m), 0.0, 1.0);
  // The event's s-axis; at normal incidence d x m = 0 and e1 is kept.
  const Vec3 dxm = d.cross(m);
  const double n = dxm.norm();
  if (n > 1e-12) rotate_reference(d, dxm / n);
  const Amplitudes a = amplitudes(cos_i, eta_rel);
  const Mueller R = reflection_matrix(a);
  const double p_reflect = R.A * stokes_[0] + R.B * stokes_[1];
  EventResult result;
  Eigen::Vector4d next;
  if (a.cos_t < 0.0 || rng.uniform() < p_reflect) {
    next = R.times(stokes_);
    result = {reflect(d, m, cos_i), false};
  } else {
    next = transmission_matrix(a).times(stokes_);
    result = {refract(d, m, cos_i, 1.0 / eta_rel, a.cos_t), true};
  }
  stokes_ = next / next[0];
  // s stays the reference axis; keep it exactly perpendicular to the new direction.
  e1_ = (e1_ - e1_.dot(result.direction) * result.direction).normalized();
  return result;
}

}  // namespace fiberlab::sim
