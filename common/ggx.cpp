#include "common/ggx.h"

#include <algorithm>
#include <cmath>

#include "common/units.h"

namespace fiberlab::ggx {

double D(const Vec3& m, double ax, double ay) {
  const double z = m.z();
  if (z <= 0.0) return 0.0;
  const double q = m.x() * m.x() / (ax * ax) + m.y() * m.y() / (ay * ay) + z * z;
  return 1.0 / (kPi * ax * ay * q * q);
}

double Lambda(const Vec3& w, double ax, double ay) {
  const double s = std::sqrt(ax * ax * w.x() * w.x() + ay * ay * w.y() * w.y());
  if (s == 0.0) return 0.0;  // w along the normal: nothing masks it
  const double a = w.z() / s;  // 1 / (alpha tan theta) in the stretched configuration
  return 0.5 * (-1.0 + std::sqrt(1.0 + 1.0 / (a * a)));
}

double G1(const Vec3& w, double ax, double ay) {
  if (w.z() <= 0.0) return 0.0;
  return 1.0 / (1.0 + Lambda(w, ax, ay));
}

Vec3 sample_visible(const Vec3& w, double ax, double ay, double u1, double u2) {
  // Heitz 2018, section 4: w stretched to the alpha = 1 hemisphere.
  const Vec3 vh = Vec3(ax * w.x(), ay * w.y(), w.z()).normalized();
  const double len2 = vh.x() * vh.x() + vh.y() * vh.y();
  const Vec3 t1 = len2 > 0.0 ? Vec3(-vh.y(), vh.x(), 0.0) / std::sqrt(len2) : Vec3(1.0, 0.0, 0.0);
  const Vec3 t2 = vh.cross(t1);
  // A uniform point of the unit disk, its second coordinate squeezed onto
  // the part of the projected hemisphere visible from vh.
  const double r = std::sqrt(u1), phi = kTwoPi * u2;
  const double p1 = r * std::cos(phi);
  double p2 = r * std::sin(phi);
  const double s = 0.5 * (1.0 + vh.z());
  p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
  const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  // Unstretch (normals transform with the inverse transpose).
  return Vec3(ax * nh.x(), ay * nh.y(), std::max(0.0, nh.z())).normalized();
}

}  // namespace fiberlab::ggx
