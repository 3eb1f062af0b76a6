#pragma once
// The GGX (Trowbridge-Reitz) microfacet distribution, in a local frame whose
// z axis is the mean (meso) normal: its normal distribution D, Smith's Lambda
// and the exact sampling map of its distribution of visible normals (VNDF).
// Shared by the simulator's `roughness: {model: ggx}` (sim/roughness/microfacet_distribution)
// and the analytic model of Huang et al. 2022 (analytic/huang2022), so the
// formulas exist once.
//
// With r^2 = m_x^2 / ax^2 + m_y^2 / ay^2 (ax, ay > 0 the roughness along x, y):
//   D(m)      = 1 / (pi ax ay (r^2 + m_z^2)^2)          (m_z > 0; else 0)
//   Lambda(w) = (-1 + sqrt(1 + 1/a^2)) / 2,  a = w_z / sqrt(ax^2 w_x^2 + ay^2 w_y^2)
//   G1(w)     = 1 / (1 + Lambda(w))
// normalised as integral D(m) m_z dm = 1 over the hemisphere (Heitz 2014,
// "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
// sections 5.1-5.3). The VNDF D_w(m) = G1(w) max(0, w.m) D(m) / w_z (unit
// integral over m) is sampled without rejection by the map of Heitz 2018,
// "Sampling the GGX Distribution of Visible Normals" (JCGT 7(4)), section 4:
// a deterministic map from the unit square, so the same function serves a
// Monte Carlo sampler (random u) and a quadrature over m (fixed u).
#include "common/fiber_frame.h"

namespace fiberlab::ggx {

// Vectors in the local frame (z = the mean normal), unit length.
double D(const Vec3& m, double ax, double ay);
double Lambda(const Vec3& w, double ax, double ay);
// G1(w) = 1 / (1 + Lambda(w)) for w_z > 0, 0 otherwise.
double G1(const Vec3& w, double ax, double ay);
// The normal m (m_z >= 0, w.m >= 0) that (u1, u2) in [0, 1)^2 maps to; the
// image of the uniform measure is D_w. Requires w_z > 0.
Vec3 sample_visible(const Vec3& w, double ax, double ay, double u1, double u2);

}  // namespace fiberlab::ggx
