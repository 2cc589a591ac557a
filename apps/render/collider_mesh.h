#pragma once
// Triangles of the runtime's colliders (qv_collider), for pictures of objects in flight: a plane as
// the square of it under the framed box, spheres, boxes and capsules tessellated, meshes as read.
#include <vector>

#include <Eigen/Core>

#include "formats/mesh/read_surface.h"
#include "quiver/quiver.h"

namespace quiver::app {

struct TriangleSoup {
  std::vector<float> positions;     // 3 per vertex
  std::vector<unsigned> triangles;  // 3 vertex indices each, counter-clockwise seen from outside
};

// Appends `collider`'s surface to `soup`; a plane is the square of side 2 x the box's diagonal
// around the point of the plane nearest the box's centre; a mesh collider is `surface` (its file's) placed.
void appendCollider(const qv_collider& collider, const SurfaceMesh* surface, const Eigen::Vector3d& boxMin,
                    const Eigen::Vector3d& boxMax, TriangleSoup& soup);

} // namespace quiver::app
