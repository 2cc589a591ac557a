// Collider triangles lie on the colliders they draw: every vertex at the signed distance 0 the
// runtime's own collider distance measures.
#include "apps/render/collider_mesh.h"

#include <cmath>

#include <gtest/gtest.h>

#include "runtime/src/contact.h"
#include "tests/support/make_collider.h"

namespace quiver::app {
namespace {

TEST(ColliderMesh, EveryVertexLiesOnItsCollider) {
  const Eigen::Vector3d lo(-1, -1, 0), hi(2, 1, 3);
  qv_collider turned = test::makeCollider(QV_COLLIDER_BOX, {1, 0, 1, 1, 2, 0.5, 0, 0});
  turned.rotation[0] = 0.3, turned.rotation[1] = -0.5, turned.rotation[2] = 1.1;
  const qv_collider colliders[] = {test::makeCollider(QV_COLLIDER_PLANE, {0, 0, 2, 1, 0, 0, 0, 0}, 0, 0),
                                   test::makeCollider(QV_COLLIDER_SPHERE, {1, 2, 3, 0.5, 0, 0, 0, 0}, 0, 0),
                                   test::makeCollider(QV_COLLIDER_BOX, {0, 0, 1, 1, 2, 0.5, 0, 0}, 0, 0),
                                   test::makeCollider(QV_COLLIDER_CAPSULE, {0, 0, 0, 1, 1, 2, 0.25, 0}, 0, 0),
                                   turned};
  for (const qv_collider& c : colliders) {
    TriangleSoup soup;
    appendCollider(c, nullptr, lo, hi, soup);
    ASSERT_GE(soup.triangles.size(), 6u) << c.type;
    for (unsigned index : soup.triangles) ASSERT_LT(index, soup.positions.size() / 3);
    for (size_t v = 0; v < soup.positions.size() / 3; ++v) {
      const double p[3] = {soup.positions[3 * v], soup.positions[3 * v + 1], soup.positions[3 * v + 2]};
      double distance, normal[3];
      ASSERT_TRUE(rt::colliderDistance(c, p, INFINITY, distance, normal));
      EXPECT_NEAR(distance, 0, 1e-6) << "collider type " << c.type << ", vertex " << v;
    }
  }
  // The plane is drawn under the box: around the point nearest its centre, wider than the box.
  TriangleSoup plane;
  appendCollider(colliders[0], nullptr, lo, hi, plane);
  EXPECT_EQ(plane.triangles.size(), 6u);
  EXPECT_NEAR(plane.positions[2], 0.5, 1e-6);
}

} // namespace
} // namespace quiver::app
