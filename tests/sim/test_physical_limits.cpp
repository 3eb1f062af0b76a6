// The bounds of fiber.eta and fiber.eccentricity (common/physical_limits.h)
// are where the double-precision physics stops being meaningful: at the
// bound it is accurate, beyond it it is not (or not finite). Oracles: the
// same formulas in long double (64-bit significand), and the exact
// transmittance T = 1 - F in a form without cancellation.
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <cfloat>
#include <cmath>
#include <random>

#include "common/error.h"
#include "common/fresnel.h"
#include "common/physical_limits.h"
#include "sim/life/ellipse_cross_section.h"
#include "sim/run/settings.h"

namespace fiberlab {
namespace {

// Worst relative error of the simulator's transmittance 1 - F over cos_i in
// [1e-3, 1], against T = (T_s + T_p) / 2 with T_s = 4 c eta ct / (c + eta ct)^2,
// T_p = 4 c eta ct / (eta c + ct)^2 in long double (no cancellation); NaN
// when F is not finite somewhere.
double worst_transmittance_error(double eta) {
  double worst = 0.0;
  for (int i = 1; i <= 1000; ++i) {
    const double c = i / 1000.0;
    const FresnelReflectanceOf<double> r = fresnel_reflectance(c, eta, 1.0 / eta);
    if (!std::isfinite(r.F)) return NAN;
    const long double e = eta, cl = c;
    const long double ct = std::sqrt(1.0L - (1.0L - cl * cl) / (e * e));
    const long double ts = 4 * cl * e * ct / ((cl + e * ct) * (cl + e * ct));
    const long double tp = 4 * cl * e * ct / ((e * cl + ct) * (e * cl + ct));
    const long double t = (ts + tp) / 2;
    worst = std::max(worst, static_cast<double>(std::fabs((1.0L - r.F - t) / t)));
  }
  return worst;
}

TEST(PhysicalLimits, TransmittanceAccurateUpToTheEtaBound) {
  // The bound's criterion: T within 1e-6 relative (common/physical_limits.h).
  EXPECT_LT(worst_transmittance_error(1.55), 1e-13);
  EXPECT_LT(worst_transmittance_error(kMaxEta), 1e-6);
  // Ten times beyond, the criterion fails; far beyond, T is lost or F is NaN.
  EXPECT_GT(worst_transmittance_error(10 * kMaxEta), 1e-6);
  EXPECT_GT(worst_transmittance_error(1e15), 1e-2);
  EXPECT_TRUE(std::isnan(worst_transmittance_error(1e80)));
}

// The geometry of one step from many boundary points, against the same
// intersection in long double (its quadratic solved with the C term): the
// worst normal angle error (radians) and relative chord error; NaN when a
// value is not finite.
std::pair<double, double> worst_geometry_error(double e) {
  const sim::EllipseCrossSection el(e);
  std::mt19937_64 g(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_normal = 0.0, worst_chord = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const long double th = 2 * M_PI * u(g);
    const double pv = static_cast<double>(std::cos(th) / std::sqrt(static_cast<long double>(e)));
    const double pw = static_cast<double>(std::sin(th) * std::sqrt(static_cast<long double>(e)));
    const double a = 2 * M_PI * u(g);
    double dv = std::cos(a), dw = std::sin(a);
    const Vec3 n = el.normal(sim::Point2(pv, pw));
    if (!std::isfinite(n.y()) || !std::isfinite(n.z())) return {NAN, NAN};
    if (dv * n.y() + dw * n.z() > 0) dv = -dv, dw = -dw;
    sim::life::MaskOf<double> along_axis = false;
    const double t = el.distance_to_boundary(pv, pw, dv, dw, along_axis);
    double qv = pv, qw = pw;
    el.advance(qv, qw, dv, dw, t);
    const Vec3 m = el.normal(sim::Point2(qv, qw));
    if (!std::isfinite(t) || !std::isfinite(m.y()) || !std::isfinite(m.z())) return {NAN, NAN};
    const long double E = e;
    const long double A = dv * (long double)dv * E + dw * (long double)dw / E;
    const long double B = 2 * (pv * (long double)dv * E + pw * (long double)dw / E);
    const long double C = pv * (long double)pv * E + pw * (long double)pw / E - 1;
    const long double tr = (-B + std::sqrt(B * B - 4 * A * C)) / (2 * A);
    long double nv = (pv + tr * dv) * E, nw = (pw + tr * dw) / E;
    const long double nn = std::sqrt(nv * nv + nw * nw);
    nv /= nn, nw /= nn;
    worst_normal = std::max(worst_normal, static_cast<double>(std::fabs(m.y() * nw - m.z() * nv)));
    if (tr > 1e-3L * std::sqrt(E))  // grazing chords: the rounding of p itself dominates (as for a circle)
      worst_chord = std::max(worst_chord, static_cast<double>(std::fabs((t - tr) / tr)));
  }
  return {worst_normal, worst_chord};
}

TEST(PhysicalLimits, EllipseGeometryAccurateDownToTheEccentricityBound) {
  for (double e : {1.0, 0.5, 1e-4, 1e-100, kMinEccentricity}) {
    const auto [normal, chord] = worst_geometry_error(e);
    EXPECT_LT(normal, 1e-8) << "eccentricity " << e;
    EXPECT_LT(chord, 1e-8) << "eccentricity " << e;
  }
  // Just below, e is subnormal: the ratio written is not the one stored
  // (1.5e-308 keeps 52 of the 53 bits); below 1/DBL_MAX, 1/e overflows and the
  // geometry is NaN.
  const double below = 1.5e-308;
  EXPECT_EQ(std::fpclassify(below), FP_SUBNORMAL);
  EXPECT_EQ(std::fpclassify(std::nextafter(kMinEccentricity, 0.0)), FP_SUBNORMAL);
  EXPECT_TRUE(std::isnan(worst_geometry_error(1.0 / DBL_MAX / 2).first));
  EXPECT_TRUE(std::isnan(worst_geometry_error(1e-310).first));
}

TEST(PhysicalLimits, ConfigAcceptsTheBoundsAndRefusesBeyond) {
  auto fiber = [](const std::string& key, double value) {
    return sim::parse_settings_yaml(fmt::format("fiber: {{{}: {:.17g}}}\n", key, value), "t.yaml");
  };
  EXPECT_EQ(fiber("eta", kMaxEta).fiber.eta, kMaxEta);
  EXPECT_THROW(fiber("eta", std::nextafter(kMaxEta, INFINITY)), Error);
  EXPECT_EQ(fiber("eccentricity", kMinEccentricity).fiber.eccentricity, kMinEccentricity);
  EXPECT_THROW(fiber("eccentricity", std::nextafter(kMinEccentricity, 0.0)), Error);
  try {
    fiber("eta", 1e80);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fiber.eta = 1e+80 is out of range (must be in (1, 1e9]"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace fiberlab
