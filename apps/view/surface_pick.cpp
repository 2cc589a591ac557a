#include "apps/view/surface_pick.h"

#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace quiver::app {

std::optional<SurfaceHit> pickSurface(const Ray& ray, const std::vector<float>& positions,
                                      const std::vector<unsigned>& triangles) {
  auto vertex = [&](unsigned v) {
    return Eigen::Vector3d(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
  };
  std::optional<SurfaceHit> best;
  for (size_t t = 0; 3 * t + 2 < triangles.size(); ++t) {
    const unsigned* c = &triangles[3 * t];
    // Moller-Trumbore: solve origin + s d = a + u (b - a) + v (c - a).
    const Eigen::Vector3d a = vertex(c[0]), e1 = vertex(c[1]) - a, e2 = vertex(c[2]) - a;
    const Eigen::Vector3d p = ray.direction.cross(e2);
    const double det = e1.dot(p);
    if (!(std::abs(det) > 1e-300)) continue;  // parallel, degenerate or NaN
    const Eigen::Vector3d s = ray.origin - a;
    const double u = s.dot(p) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = ray.direction.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    const double along = e2.dot(q) / det;
    if (along <= 0 || (best && along >= best->distance)) continue;
    const Eigen::Vector3d point = ray.origin + along * ray.direction;
    int nearest = 0;
    for (int k = 1; k < 3; ++k)
      if ((vertex(c[k]) - point).squaredNorm() < (vertex(c[nearest]) - point).squaredNorm()) nearest = k;
    best = SurfaceHit{static_cast<int>(t), static_cast<int>(c[nearest]), along, point};
  }
  return best;
}

std::optional<Eigen::Vector3d> intersectPlane(const Ray& ray, const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  const double facing = ray.direction.dot(normal);
  if (std::abs(facing) < 1e-12) return std::nullopt;
  const double along = (point - ray.origin).dot(normal) / facing;
  if (along <= 0) return std::nullopt;
  return ray.origin + along * ray.direction;
}

} // namespace quiver::app
