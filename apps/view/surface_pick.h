#pragma once
// Which surface point a ray hits first: the viewer's "what is under the cursor".
#include <optional>
#include <vector>

#include "apps/view/orbit_camera.h"

namespace quiver::app {

struct SurfaceHit {
  int triangle;          // index into the triangle list
  int vertex;            // the hit triangle's corner nearest the hit point
  double distance;       // along the ray
  Eigen::Vector3d point;
};

// Nearest hit of `ray` with `triangles` (3 vertex indices each) over `positions` (3 floats per
// vertex), from either side; nothing when the ray misses them all.
std::optional<SurfaceHit> pickSurface(const Ray& ray, const std::vector<float>& positions,
                                      const std::vector<unsigned>& triangles);

// Where `ray` crosses the plane through `point` facing `normal`; nothing when parallel or behind.
std::optional<Eigen::Vector3d> intersectPlane(const Ray& ray, const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

} // namespace quiver::app
