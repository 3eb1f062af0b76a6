#pragma once
// Dielectric Fresnel reflectance, shared by the simulator and the analytic models.

namespace fiberlab {

// Unpolarised reflectance F = (Rs + Rp) / 2 for light arriving at an interface
// with cos_i = cosine of the angle between the ray and the normal (>= 0) and
// eta_rel = n_t / n_i (the index on the far side over the index on the near
// side). Total internal reflection returns 1. Textbook form, e.g. Born & Wolf
// section 1.5.2; pbrt-v4 FrDielectric.
double fresnel_dielectric(double cos_i, double eta_rel);

// Fresnel s and p amplitude reflectances r_s and r_p (real, no TIR) with the
// sign convention of SPEC section 3: r_p = -r_s at normal incidence.
struct FresnelAmplitudes {
  double cos_t;  // cosine of the refraction angle; NaN under TIR
  double r_s, r_p;
};
FresnelAmplitudes fresnel_amplitudes(double cos_i, double eta_rel);

}  // namespace fiberlab
