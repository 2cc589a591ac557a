#pragma once
// qv_triangle_mesh: a closed, consistently oriented triangle mesh as a signed distance: the
// closest point found through a bounding-volume hierarchy, its sign from the angle-weighted
// pseudo-normal of the face, edge or vertex it lies on (Baerentzen & Aanaes 2005), which is exact
// for any closed manifold mesh, convex or not. One block from the caller's allocator; immutable,
// shared read-only by any number of colliders, instances and threads.
#include <cstddef>

#include "quiver/quiver.h"

namespace quiver::rt {

struct BvhNode {
  double lo[3], hi[3];
  int first;  // leaf: its first triangle in `order`; inner node: its first child (the second follows)
  int count;  // leaf: its triangles; 0: an inner node
};

} // namespace quiver::rt

struct qv_triangle_mesh {
  qv_allocator allocator;
  int vertexCount = 0, triangleCount = 0, nodeCount = 0;
  const double* vertices = nullptr;       // 3 per vertex
  const int* triangles = nullptr;         // 3 per triangle, outward by the right-hand rule
  const double* faceNormals = nullptr;    // 3 per triangle, unit
  const double* edgeNormals = nullptr;    // 9 per triangle: edge (i, i+1)'s pseudo-normal, unit
  const double* vertexNormals = nullptr;  // 3 per vertex: angle-weighted, unit
  const int* order = nullptr;             // triangles in leaf order
  const quiver::rt::BvhNode* nodes = nullptr;  // nodes[0] is the root

  // Signed distance of `p` (negative inside) and the outward unit normal there: the direction
  // from the closest surface point to p outside, from p to it inside. False when p is farther
  // than `reach` outside the mesh's bounding box (nothing computed). `triangle`, when not null,
  // receives the closest triangle. With `facing` (a unit direction), only the triangles facing
  // against it count: the distance to the nearest of them, negative on the inner side of its plane,
  // and its normal (false when there is none). `hint`: a triangle likely nearest (one a query of a
  // point nearby found), measured first so that the search skips every box farther than it; the
  // same distance comes out.
  bool distance(const double p[3], double reach, double& distance, double normal[3], int* triangle = nullptr,
                const double* facing = nullptr, int hint = -1) const;
};

namespace quiver::rt {

// Builds the mesh in one block from `allocator`, after checking it: finite positions, indices in
// range, no degenerate triangle, every edge shared by exactly two triangles that run it in
// opposite directions (closed, manifold, consistently oriented). An inward-facing mesh (negative
// enclosed volume) is turned outward. On a bad mesh returns QV_ERROR_FORMAT and says what and where.
qv_result createTriangleMesh(const double* positions, int vertexCount, const int* triangles, int triangleCount,
                             const qv_allocator& allocator, qv_triangle_mesh** mesh, char* message, size_t messageSize);
void destroyTriangleMesh(qv_triangle_mesh* mesh);

} // namespace quiver::rt
