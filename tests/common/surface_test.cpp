#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/box_mesh.h"
#include "common/surface.h"

using namespace quiver;

// For a closed, outward-oriented surface: sum of area vectors is zero and (1/3) sum of x . n dA
// is the enclosed volume (divergence theorem); the total area of a box is known.
TEST(Surface, BoxBoundaryIsClosedOutwardAndComplete) {
  const Eigen::Vector3d size(2, 0.5, 0.3);
  TetMesh mesh = makeBoxMesh(size, {4, 3, 2});
  const auto tris = boundaryTriangles(mesh);
  EXPECT_EQ(tris.size(), 2u * 2 * (4 * 3 + 4 * 2 + 3 * 2));  // two triangles per boundary cell face
  Eigen::Vector3d areaVector = Eigen::Vector3d::Zero();
  double area = 0, volume = 0;
  for (const auto& t : tris) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d n2 = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);  // 2 x area x normal
    areaVector += n2 / 2;
    area += n2.norm() / 2;
    volume += a.dot(n2) / 6;
  }
  EXPECT_LT(areaVector.norm(), 1e-12);
  EXPECT_NEAR(area, 2 * (2 * 0.5 + 2 * 0.3 + 0.5 * 0.3), 1e-12);
  EXPECT_NEAR(volume, 2 * 0.5 * 0.3, 1e-12);  // positive: the normals point out
}
