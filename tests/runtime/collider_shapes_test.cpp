// Turned boxes, triangle meshes and kinematic colliders, against mechanics worked by hand: a bar
// slides down a ramp at g (sin a - mu cos a) and rests on one steeper than its friction holds; a
// ramp made of a triangle mesh does the same; a bar flush with a table's edge stays on it; a moving
// platform carries what rests on it, a rising floor lifts it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dropped_bar.h"
#include "tests/support/box_surface.h"
#include "tests/support/make_collider.h"

namespace quiver {
namespace {

using test::Dropped;
using test::makeCollider;

constexpr double kG = QV_STANDARD_GRAVITY;

// A slab [-3, 3] x [-1, 1] x [-0.5, 0.5] as 12 triangles, for a mesh collider.
struct SlabMesh {
  qv_triangle_mesh* mesh = nullptr;
  SlabMesh() {
    const double half[3] = {3, 1, 0.5};
    const test::BoxSurface s = test::boxSurface(half);
    EXPECT_EQ(qv_triangle_mesh_create(s.positions.data(), 8, s.triangles.data(), 12, nullptr, &mesh, nullptr, 0), QV_OK);
  }
  ~SlabMesh() { qv_triangle_mesh_destroy(mesh); }
};

// The bar lying on a ramp descending along +x at `angle` (the slab turned about y), 2 mm above it;
// returns the bar's acceleration down the slope between 0.2 s and 0.6 s.
double slideDownRamp(double angle, double mu, const qv_triangle_mesh* mesh) {
  qv_collider ramp = mesh ? makeCollider(QV_COLLIDER_MESH, {0, 0, 0, 0, 0, 0, 0, 0}, mu, 0)
                          : makeCollider(QV_COLLIDER_BOX, {0, 0, 0, 3, 1, 0.5, 0, 0}, mu, 0);
  ramp.mesh = mesh;
  ramp.rotation[1] = angle;
  const double normal[3] = {std::sin(angle), 0, std::cos(angle)}, down[3] = {std::cos(angle), 0, -std::sin(angle)};
  qv_rigid_state start{};
  for (int a = 0; a < 3; ++a) start.position[a] = (0.5 + 0.052) * normal[a];
  start.orientation[0] = std::cos(angle / 2), start.orientation[2] = std::sin(angle / 2);
  Dropped d(1.0 / 120, {ramp}, start, 5);
  double v[2] = {};
  for (int i = 1; i <= 72; ++i) {
    EXPECT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
    const qv_rigid_state s = d.state();
    const double along = s.linear_velocity[0] * down[0] + s.linear_velocity[2] * down[2];
    if (i == 24) v[0] = along;
    if (i == 72) v[1] = along;
  }
  return (v[1] - v[0]) / 0.4;
}

TEST(ColliderShapes, ABarSlidesDownATurnedBoxAndATriangleMeshAtGTimesSinLessMuCos) {
  const double angle = M_PI / 6, mu = 0.3, expected = kG * (std::sin(angle) - mu * std::cos(angle));
  SlabMesh slab;
  const double box = slideDownRamp(angle, mu, nullptr), mesh = slideDownRamp(angle, mu, slab.mesh);
  std::printf("down a 30 degree ramp with mu 0.3: %.4f m/s^2 on a turned box, %.4f on a triangle mesh; "
              "g (sin a - mu cos a) = %.4f\n", box, mesh, expected);
  EXPECT_NEAR(box, expected, 0.03 * expected);
  EXPECT_NEAR(mesh, expected, 0.03 * expected);
  // Shallower than atan(mu) = 16.7 degrees: friction holds it.
  const double held = slideDownRamp(M_PI / 18, mu, slab.mesh);
  std::printf("on a 10 degree ramp: %.2e m/s^2\n", held);
  EXPECT_LT(std::fabs(held), 0.01);
}

// A bar laid on a table flush with its edge, as a box and as a triangle mesh: each vertex of the
// bar's side lies on the table's edge, nearest the table's side face. Those sideways normals rolled
// it off the table within a quarter second (measured); it stays, level.
TEST(ColliderShapes, ABarFlushWithATablesEdgeStaysOnIt) {
  SlabMesh slab;
  for (const bool mesh : {false, true}) {
    // The slab [-3, 3] x [-1, 1] x [-0.5, 0.5] moved so that its top is at z = 0 and its +y side at
    // y = 0.05, where the bar's side is (the bar's centre at the origin, 0.1 m wide and high).
    qv_collider table = makeCollider(mesh ? QV_COLLIDER_MESH : QV_COLLIDER_BOX, {0, -0.95, -0.5, 3, 1, 0.5, 0, 0}, 0.5, 0);
    table.mesh = mesh ? slab.mesh : nullptr;
    qv_rigid_state start{};
    start.position[2] = 0.055;
    start.orientation[0] = 1;
    Dropped d(1.0 / 60, {table}, start);
    for (int i = 0; i < 240; ++i) ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
    const qv_rigid_state s = d.state();
    const double tilt = 2 * std::asin(std::hypot(s.orientation[1], s.orientation[2]));
    std::printf("bar flush with a %s table's edge after 4 s: centre at y %.2e, z %.4f m; tilted %.3g degrees\n",
                mesh ? "triangle mesh" : "box", s.position[1], s.position[2], tilt * 180 / M_PI);
    EXPECT_NEAR(s.position[1], 0, 1e-3);
    EXPECT_NEAR(s.position[2], 0.05, 3e-3);
    EXPECT_LT(tilt, 0.5 * M_PI / 180);
  }
}

TEST(ColliderShapes, AMovingPlatformCarriesWhatRestsOnItAndARisingFloorLiftsIt) {
  // A belt: a box whose top is at z = 0, moving along x at 0.5 m/s; the bar dropped on it at rest.
  const double belt = 0.5, h = 1.0 / 120;
  qv_collider platform = makeCollider(QV_COLLIDER_BOX, {0, 0, -0.5, 5, 1, 0.5, 0, 0}, 0.5, 0);
  platform.velocity[0] = belt;
  Dropped carried(h, {platform}, {{0.3, 0.05, 0.052}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}});
  double reached = -1;
  for (int i = 1; i <= 60; ++i) {
    carried.colliders[0].data[0] += belt * h;  // the game moves it
    ASSERT_NE(qv_instance_step(carried.inst->s), QV_STEP_RESET);
    if (reached < 0 && carried.state().linear_velocity[0] > 0.99 * belt) reached = i * h;
  }
  // Kinetic friction accelerates it at mu g until it moves with the belt: v / (mu g) = 0.102 s.
  std::printf("on a belt at %.1f m/s: at its speed after %.3f s (v / (mu g) = %.3f s), %.4f m/s after 0.5 s\n", belt,
              reached, belt / (0.5 * kG), carried.state().linear_velocity[0]);
  EXPECT_NEAR(reached, belt / (0.5 * kG), 0.1 * belt / (0.5 * kG));
  EXPECT_NEAR(carried.state().linear_velocity[0], belt, 0.01 * belt);

  // An elevator: the ground plane z = d rising at 0.3 m/s under the resting bar.
  const double rise = 0.3;
  qv_collider floor = makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0);
  floor.velocity[2] = rise;
  Dropped lifted(h, {floor}, {{0.3, 0.05, 0.051}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}});
  for (int i = 1; i <= 120; ++i) {
    lifted.colliders[0].data[3] += rise * h;
    ASSERT_NE(qv_instance_step(lifted.inst->s), QV_STEP_RESET);
  }
  const qv_rigid_state s = lifted.state();
  std::printf("on a floor rising at %.1f m/s: %.4f m/s after 1 s, its centre %.4f m above the floor (rest 0.05)\n",
              rise, s.linear_velocity[2], s.position[2] - lifted.colliders[0].data[3]);
  EXPECT_NEAR(s.linear_velocity[2], rise, 0.01 * rise);
  EXPECT_NEAR(s.position[2] - lifted.colliders[0].data[3], 0.05, 3e-3);
}

} // namespace
} // namespace quiver
