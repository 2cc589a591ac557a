// Contact of a flying bar with colliders, against mechanics worked by hand: at rest on a plane the
// contacts carry exactly its weight; sliding stops after v0 / (mu g); a bounce never gains energy;
// the colliders' signed distances against geometry; bad colliders refused; with soft contacts, a
// soft bar lies straight on the ground (with either solver and either implicit integrator).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <tuple>
#include <vector>

#include "dropped_bar.h"
#include "runtime/src/contact.h"
#include "runtime/src/instance.h"
#include "runtime/src/triangle_mesh.h"
#include "runtime_fixture.h"
#include "tests/support/make_collider.h"

namespace quiver {
namespace {

using test::Dropped;
using test::FreeBar;
using test::makeCollider;

constexpr double kG = QV_STANDARD_GRAVITY;

qv_collider ground(double friction, double restitution) {
  return makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, friction, restitution);
}

TEST(Contact, AtRestOnAPlaneItCarriesExactlyItsWeight) {
  // Lying flat, its underside 2 cm above the ground.
  Dropped d(1.0 / 60, {ground(0.5, 0)}, {{0.3, 0.05, 0.07}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, 5, {12, 2, 2});
  double landing = 0, deepest = 0;  // the deepest any deformed vertex sinks, landing and at rest
  for (int i = 0; i < 180; ++i) {
    ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
    double f[3], pen;
    d.contactForce(f, pen);
    landing = std::max(landing, pen);
  }
  const qv_rigid_state before = d.state();
  double mean = 0;
  for (int i = 0; i < 60; ++i) {
    ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
    double f[3], pen;
    d.contactForce(f, pen);
    mean += f[2] / 60;
    deepest = std::max(deepest, pen);
  }
  const qv_rigid_state after = d.state();
  const double weight = d.bar.info.total_mass * kG;
  double creep = 0;
  for (int a = 0; a < 3; ++a) creep += std::pow(after.position[a] - before.position[a], 2);
  std::printf("at rest: contact force %.6g N for a weight of %.6g N, creep %.3g m/s, deepest penetration %.3g m "
              "(landing %.3g m)\n", mean, weight, std::sqrt(creep), deepest, landing);
  EXPECT_NEAR(mean, weight, 1e-3 * weight);
  EXPECT_LT(std::sqrt(creep), 1e-6);                 // over the last second (1.7e-4 before the warm start)
  EXPECT_LT(deepest, 5e-3 * 0.62);                   // the slop (1e-3 of the diagonal), the softness, the deformation
  EXPECT_LT(landing, 6e-3 * 0.62);
  EXPECT_NEAR(after.position[2], 0.05, 3e-3 * 0.62);  // resting on its underside
  // Flat on the ground: its underside straight (a flutter between loaded ends and loaded middle once
  // bent it by 1.5 cm).
  const Eigen::MatrixXd x = d.bar.positions(d.inst->s);
  const double* rest = qv_model_rest_positions(d.bar.model);
  double low = INFINITY, high = -INFINITY;
  for (int v = 0; v < d.bar.info.vertex_count; ++v)
    if (rest[3 * v + 2] < 1e-9) low = std::min(low, x(v, 2)), high = std::max(high, x(v, 2));
  std::printf("its underside between z = %.4g and %.4g m\n", low, high);
  EXPECT_LT(high - low, 2e-3);
}

TEST(Contact, AFaceWithMoreVerticesThanContactsRestsOnAllOfIt) {
  // Undersides of 25 x 3 and 41 x 3 vertices on the ground, more than the 64 contacts an instance
  // keeps: keeping the deepest 64 kept one end, then the other as it tilted, and it rocked forever
  // (5e-4 m/s, 6e-3 rad/s after 4 s with 75 vertices).
  // Each set down 2 cm above the ground, then thrown down flat at 3 m/s from 0.3 m (when all its
  // vertices are within the step's reach, and the deepest 64 are kept until it touches), after a
  // bar of 13 x 3 underside vertices (all kept) thrown the same way: how deep its soft (1 MPa)
  // deformation sinks.
  double thrown = 0;
  for (const auto& [cells, height, speed] : {std::tuple{12, 0.3, -3.0}, {24, 0.07, 0.0}, {40, 0.07, 0.0}, {40, 0.3, -3.0}}) {
    Dropped d(1.0 / 60, {ground(0.5, 0)}, {{0.3, 0.05, height}, {1, 0, 0, 0}, {0, 0, speed}, {0, 0, 0}}, 5, {cells, 2, 2});
    double landing = 0;
    for (int i = 0; i < 240; ++i) {
      ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
      double f[3], pen;
      d.contactForce(f, pen);
      landing = std::max(landing, pen);
    }
    double fastest = 0, spin = 0, mean = 0, low = 0, high = INFINITY;  // the least span of the contacts in a step
    int most = 0;
    for (int i = 0; i < 60; ++i) {
      ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
      const qv_rigid_state s = d.state();
      fastest = std::max(fastest, std::hypot(s.linear_velocity[0], s.linear_velocity[1], s.linear_velocity[2]));
      spin = std::max(spin, std::hypot(s.angular_velocity[0], s.angular_velocity[1], s.angular_velocity[2]));
      double f[3], pen;
      d.contactForce(f, pen);
      mean += f[2] / 60;
      std::vector<qv_contact> contacts(64);
      const int n = qv_instance_contacts(d.inst->s, contacts.data(), 64);
      most = std::max(most, n);
      double left = INFINITY, right = -INFINITY;
      for (int j = 0; j < std::min(n, 64); ++j) left = std::min(left, contacts[j].point[0]), right = std::max(right, contacts[j].point[0]);
      low = std::max(low, left), high = std::min(high, right);
    }
    const double weight = d.bar.info.total_mass * kG;
    std::printf("%d underside vertices, at most %d contacts: over the last second speed <= %.3g m/s, spin <= %.3g rad/s, "
                "contact force %.6g N for a weight of %.6g N, contacts in every step from x = %.3g to %.3g m of 0 to 0.6; "
                "landing at %.3g m/s it sank %.3g m\n", 3 * (cells + 1), most, fastest, spin, mean, weight, low, high, std::fabs(speed), landing);
    EXPECT_LE(most, 64);
    EXPECT_LT(fastest, 1e-6);  // all 39 of a 12-cell bar: 1e-8 m/s, 7e-5 rad/s
    EXPECT_LT(spin, 1e-3);
    EXPECT_NEAR(mean, weight, 1e-3 * weight);
    EXPECT_LT(low, 0.05);  // both ends held
    EXPECT_GT(high, 0.55);
    if (cells == 12) thrown = landing;
    EXPECT_LT(landing, speed ? 1.6 * thrown : 6e-3 * 0.62);  // 7 mm and 10 mm thrown; as AtRestOnAPlane... set down
  }
}

TEST(Contact, SlidingStopsAfterV0OverMuG) {
  const double mu = 0.4, v0 = 2;
  Dropped d(1.0 / 120, {ground(mu, 0)}, {{0.3, 0.05, 0.05}, {1, 0, 0, 0}, {v0, 0, 0}, {0, 0, 0}});
  double stopped = -1;
  for (int i = 1; i <= 240 && stopped < 0; ++i) {
    ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
    if (d.state().linear_velocity[0] < 1e-3) stopped = i * d.h;
  }
  const double expected = v0 / (mu * kG);
  std::printf("sliding at %.1f m/s with mu %.1f: stopped after %.4f s, v0 / (mu g) = %.4f s\n", v0, mu, stopped, expected);
  EXPECT_NEAR(stopped, expected, 0.03 * expected);
}

// Energy (frame and deformation, kinetic, elastic and gravity's) over `steps` steps: at the start, the
// highest, and how high the centre rose after the first contact.
struct Bounce {
  double start = 0, highest = 0, end = 0, rise = 0;
};
Bounce bounce(Dropped& d, int steps) {
  const double m = d.bar.info.total_mass;
  const auto energy = [&] {
    double kinetic = 0, elastic = 0;
    qv_instance_energies(d.inst->s, &kinetic, &elastic);
    return kinetic + elastic + m * kG * d.state().position[2];
  };
  Bounce b;
  b.start = b.highest = energy();
  double lowest = INFINITY;
  bool touched = false;
  for (int i = 0; i < steps; ++i) {
    EXPECT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
    touched = touched || qv_instance_contacts(d.inst->s, nullptr, 0) > 0;
    b.highest = std::max(b.highest, energy());
    const double z = d.state().position[2];
    if (touched) lowest = std::min(lowest, z), b.rise = std::max(b.rise, z - lowest);
  }
  b.end = energy();
  return b;
}

TEST(Contact, ABounceNeverGainsEnergy) {
  // Flat onto the ground from 0.3 m: the centre comes back up by about e^2 of the fall.
  const double e = 0.8, fall = 0.3;
  Dropped flat(1.0 / 120, {ground(0.3, e)}, {{0.3, 0.05, 0.05 + fall}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, 0);
  const Bounce b = bounce(flat, 240);
  std::printf("flat drop, restitution %.1f: energy %.4g J at the start, at most %+.2e relative above it, %.4g J after 2 s; "
              "rebound %.3g m of a %.2g m fall (e^2: %.3g)\n", e, b.start, b.highest / b.start - 1, b.end, b.rise, fall,
              e * e * fall);
  EXPECT_LE(b.highest, b.start * (1 + 1e-3));
  EXPECT_GT(b.rise, 0.7 * e * e * fall);
  EXPECT_LT(b.rise, 1.15 * e * e * fall);  // from its lowest, where it squashed
  // Tumbling onto the ground and a sphere: corners, spin, two colliders.
  Dropped tumbling(1.0 / 120, {ground(0.3, e), makeCollider(QV_COLLIDER_SPHERE, {1.2, 0.05, 0.2, 0.3, 0, 0, 0, 0}, 0.3, e)},
                   {{0.3, 0.05, 0.6}, {0.96, 0.1, 0.2, 0.15}, {1.5, 0, 0}, {0, 1, 0}}, 0);
  const Bounce t = bounce(tumbling, 360);
  std::printf("tumbling drop: energy %.4g J at the start, at most %+.2e relative above it, %.4g J after 3 s\n", t.start,
              t.highest / t.start - 1, t.end);
  EXPECT_LE(t.highest, t.start * (1 + 1e-3));
}

TEST(Contact, CollidersMeasureDistanceAsGeometrySays) {
  double d, n[3];
  const double p[3] = {1, 2, 3};
  ASSERT_TRUE(rt::colliderDistance(makeCollider(QV_COLLIDER_PLANE, {0, 0, 2, 2, 0, 0, 0, 0}, 0, 0), p, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, 2);  // z = 1, normal +z
  EXPECT_EQ(n[2], 1);
  ASSERT_TRUE(rt::colliderDistance(makeCollider(QV_COLLIDER_SPHERE, {1, 2, 0, 1, 0, 0, 0, 0}, 0, 0), p, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, 2);
  ASSERT_TRUE(rt::colliderDistance(makeCollider(QV_COLLIDER_BOX, {0, 0, 0, 2, 3, 1, 0, 0}, 0, 0), p, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, 2);  // above the top face z = 1, inside in x and y
  EXPECT_EQ(n[2], 1);
  const double inside[3] = {1.5, 0, 0};
  ASSERT_TRUE(rt::colliderDistance(makeCollider(QV_COLLIDER_BOX, {0, 0, 0, 2, 3, 1, 0, 0}, 0, 0), inside, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, -0.5);  // nearest face x = 2
  EXPECT_EQ(n[0], 1);
  ASSERT_TRUE(rt::colliderDistance(makeCollider(QV_COLLIDER_BOX, {0, 0, 0, 0.5, 1, 2, 0, 0}, 0, 0), p, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, std::sqrt(0.25 + 1 + 1));  // past a corner
  ASSERT_TRUE(rt::colliderDistance(makeCollider(QV_COLLIDER_CAPSULE, {0, 2, 3, 0, 2, 10, 0.5, 0}, 0, 0), p, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, 0.5);  // beside the segment
  ASSERT_TRUE(rt::colliderDistance(makeCollider(QV_COLLIDER_CAPSULE, {0, 2, 5, 0, 2, 10, 0.5, 0}, 0, 0), p, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, std::sqrt(5.0) - 0.5);  // past its end cap
}

// A snapshot taken in contact carries the contacts the next step warm-starts from: a bar sliding
// and tumbling to rest on the ground and a sphere, saved while they hold, rewinds bit for bit (the
// positions and the contacts reported), and reports right after restoring the contacts it was
// saved with. Without them the next step started cold and 20 steps on the bar's vertices stood
// 1.7e-3 m (the norm of all their differences) from where they had. Crafted contacts are refused.
TEST(Contact, ASnapshotTakenInContactRewindsBitForBit) {
  Dropped d(1.0 / 60, {ground(0.5, 0), makeCollider(QV_COLLIDER_SPHERE, {0.9, 0.05, 0.1, 0.15, 0, 0, 0, 0}, 0.5, 0)},
            {{0.3, 0.05, 0.15}, {0.96, 0.1, 0.2, 0.15}, {1.5, 0, 0}, {0, 1, 0}});
  for (int i = 0; i < 30; ++i) ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
  const auto contacts = [&] {
    std::vector<qv_contact> out(64);
    out.resize(static_cast<size_t>(std::min(qv_instance_contacts(d.inst->s, out.data(), 64), 64)));
    return std::vector<char>(reinterpret_cast<const char*>(out.data()), reinterpret_cast<const char*>(out.data() + out.size()));
  };
  const std::vector<char> saved = contacts();
  ASSERT_GT(saved.size(), 3 * sizeof(qv_contact)) << "not in contact";
  std::vector<char> snapshot(qv_instance_snapshot_size(d.inst->s));
  const size_t used = qv_instance_save_snapshot(d.inst->s, snapshot.data());
  EXPECT_LT(used, snapshot.size());  // room for 64 contacts; fewer held
  for (int i = 0; i < 20; ++i) ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
  const Eigen::MatrixXd first = d.bar.positions(d.inst->s);
  const std::vector<char> firstContacts = contacts();
  ASSERT_EQ(qv_instance_restore_snapshot(d.inst->s, snapshot.data(), used), QV_OK);
  EXPECT_TRUE(contacts() == saved);
  for (int i = 0; i < 20; ++i) ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
  EXPECT_EQ(d.bar.positions(d.inst->s), first) << "moved apart by " << (d.bar.positions(d.inst->s) - first).norm();
  EXPECT_TRUE(contacts() == firstContacts);
  // The whole block restores too, and a size short of what was used is refused.
  ASSERT_EQ(qv_instance_restore_snapshot(d.inst->s, snapshot.data(), snapshot.size()), QV_OK);
  EXPECT_TRUE(contacts() == saved);
  EXPECT_EQ(qv_instance_restore_snapshot(d.inst->s, snapshot.data(), used - sizeof(double)), QV_ERROR_INVALID_ARGUMENT);
  // Refused (quiver::rt::kContactRecord = 20 doubles a contact after their count): more contacts
  // than the instance holds, one on another body, one touching neither a collider nor a body.
  const size_t count = used / sizeof(double) - 1 - 20 * (saved.size() / sizeof(qv_contact));
  const auto refused = [&](size_t at, double value) {
    std::vector<char> spoiled = snapshot;
    reinterpret_cast<double*>(spoiled.data())[at] = value;
    return qv_instance_restore_snapshot(d.inst->s, spoiled.data(), spoiled.size()) == QV_ERROR_INVALID_ARGUMENT;
  };
  EXPECT_FALSE(refused(count + 1 + 4, 1e3));  // a point elsewhere: only reported
  ASSERT_EQ(qv_instance_restore_snapshot(d.inst->s, snapshot.data(), used), QV_OK);
  EXPECT_TRUE(refused(count, 65));
  EXPECT_TRUE(refused(count + 1, 1));
  EXPECT_TRUE(refused(count + 1 + 2, -1));
  EXPECT_TRUE(contacts() == saved);
}

// The contact solve's impulses act through the frame's world inverse inertia as one matrix
// (RigidFrame::inverseInertiaMatrix()): for a deformed, turned bar it inverts R I(q) R^T, built
// here from I(q) and R themselves, and is symmetric.
TEST(Contact, TheSolvesInverseInertiaInvertsTheWorldInertia) {
  Dropped d(1.0 / 60, {}, {{0, 0, 1}, {0.96, 0.1, 0.2, 0.15}, {0, 0, 0}, {1, 2, 3}});
  std::vector<double> q(d.bar.info.r, 0.0);
  for (size_t i = 0; i < q.size(); ++i) q[i] = 0.02 * std::cos(1.0 + i);
  qv_instance_set_state(d.inst->s, q.data(), nullptr, nullptr);
  const rt::RigidFrame& f = d.inst->s->frame;
  const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(f.rotation);
  const Eigen::Matrix3d I = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(f.inertia);
  double m[9];
  f.inverseInertiaMatrix(m);
  const Eigen::Matrix3d inverse = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m);
  EXPECT_LT((inverse * R * I * R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((inverse - inverse.transpose()).norm(), 1e-12 * inverse.norm());
  EXPECT_GT((I - I.trace() / 3 * Eigen::Matrix3d::Identity()).norm(), 0.1 * I.norm());  // not round: R matters
}

// A pair of bodies whose contact points' boxes are apart (rt::boxesApart) is skipped by the narrow
// phase: none of the first's contact points may lie within the margin of the second's surface,
// which the second's own closest-point query measures here, for 20000 pairs of bars turned every
// way and placed within their spheres' reach: rigid, and with soft contacts, bent and twisted so
// that their deformed points (qv_instance_positions) leave the rest shape's box. And the skip is
// not idle: it takes many such pairs.
TEST(Contact, BodiesWhoseBoxesAreApartHaveNoContactPointWithinTheMargin) {
  FreeBar bar(10, {6, 1, 1});
  for (const bool soft : {false, true}) {
    qv_instance_config config = bar.config(1.0 / 60);
    config.soft_contacts = soft;
    test::Instance a(bar.model, config), b(bar.model, config);
    ASSERT_EQ(a.s->deformedSurface != nullptr, soft);
    const qv_model& m = *a.s->model;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(-1, 1), margins(0, 0.05);
    const auto turned = [&](const Eigen::Vector3d& position) {
      Eigen::Vector4d q(unit(rng), unit(rng), unit(rng), unit(rng));
      q.normalize();
      return qv_rigid_state{{position.x(), position.y(), position.z()}, {q[0], q[1], q[2], q[3]}, {0, 0, 0}, {0, 0, 0}};
    };
    std::vector<double> q(bar.info.r, 0.0);
    int near = 0, skipped = 0;
    double outside = 0;  // the farthest a deformed point left the rest box
    for (int trial = 0; trial < 20000; ++trial) {
      const double margin = margins(rng);
      const Eigen::Vector3d where = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * 0.7;
      qv_rigid_state sa = turned(Eigen::Vector3d::Zero()), sb = turned(where);
      if (soft) {
        for (double& x : q) x = 0.05 * unit(rng);
      }
      qv_instance_set_state(a.s, q.data(), nullptr, nullptr);
      ASSERT_EQ(qv_instance_set_rigid_state(a.s, &sa), QV_OK);
      ASSERT_EQ(qv_instance_set_rigid_state(b.s, &sb), QV_OK);
      if (where.norm() > a.s->surfaceRadius + b.s->surfaceRadius + margin) continue;
      ++near;
      if (soft) rt::deformSurface(*a.s);
      const Eigen::MatrixXd x = bar.positions(a.s);  // world, deformed
      double closest = INFINITY;  // of a's contact points to b's surface, signed
      for (int k = 0; k < a.s->surfaceCount; ++k) {
        const int v = a.s->surfaceVertices[k];
        double world[3], rel[3], local[3], body[3], distance, normal[3];
        for (int c = 0; c < 3; ++c) body[c] = m.rest[3 * v + c] - m.rigidBody[c];
        a.s->frame.toWorld(body, world);  // rigid: the rest shape carried by the frame
        for (int c = 0; c < 3; ++c) rel[c] = (soft ? x(v, c) : world[c]) - b.s->frame.position[c];
        b.s->frame.toBody(rel, local);
        for (int c = 0; c < 3; ++c) local[c] += m.rigidBody[c];
        ASSERT_TRUE(m.surfaceMesh->distance(local, INFINITY, distance, normal));
        closest = std::min(closest, distance);
        if (soft) {
          for (int c = 0; c < 3; ++c) rel[c] = x(v, c) - a.s->frame.position[c];
          a.s->frame.toBody(rel, body);
          for (int c = 0; c < 3; ++c)
            outside = std::max({outside, body[c] - (m.info.bbox_max[c] - m.rigidBody[c]), (m.info.bbox_min[c] - m.rigidBody[c]) - body[c]});
        }
      }
      if (!rt::boxesApart(*a.s, *b.s, margin)) continue;
      ++skipped;
      // (qv_instance_positions gives floats: a micron covers their rounding)
      ASSERT_GT(closest, margin - (soft ? 1e-6 : 0)) << (soft ? "soft" : "rigid") << " trial " << trial << ": skipped with a point " << closest
                                 << " m from the other's surface";
    }
    std::printf("%s: %d pairs within their spheres' reach, %d skipped; deformed points up to %.3f m outside the rest box\n",
                soft ? "soft" : "rigid", near, skipped, outside);
    EXPECT_GT(near, 5000);
    EXPECT_GT(skipped, near / 4);
    if (soft) {
      EXPECT_GT(outside, 0.02);
    }
  }
}

TEST(Contact, BadCollidersAndGroundedInstancesAreRefused) {
  FreeBar bar;
  test::Instance flying(bar.model, bar.config(1.0 / 60));
  const qv_collider bad[] = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 0, 1, 0, 0, 0, 0}, 0.5, 0),
                             makeCollider(QV_COLLIDER_SPHERE, {0, 0, 0, -1, 0, 0, 0, 0}, 0.5, 0),
                             makeCollider(QV_COLLIDER_BOX, {0, 0, 0, 1, 1, 0, 0, 0}, 0.5, 0),
                             makeCollider(QV_COLLIDER_CAPSULE, {0, 0, 0, 1, 1, 1, 0, 0}, 0.5, 0),
                             makeCollider(QV_COLLIDER_SPHERE, {0, NAN, 0, 1, 0, 0, 0, 0}, 0.5, 0),
                             makeCollider(QV_COLLIDER_SPHERE, {0, 0, 0, 1, 0, 0, 0, 0}, -1, 0),
                             makeCollider(QV_COLLIDER_SPHERE, {0, 0, 0, 1, 0, 0, 0, 0}, 0.5, 1.5),
                             makeCollider(static_cast<qv_collider_type>(9), {0, 0, 0, 1, 0, 0, 0, 0}, 0.5, 0)};
  for (const qv_collider& c : bad) EXPECT_EQ(qv_instance_set_colliders(flying.s, &c, 1), QV_ERROR_INVALID_ARGUMENT);
  const qv_collider good = ground(0.5, 0);
  EXPECT_EQ(qv_instance_set_colliders(flying.s, &good, 1), QV_OK);
  EXPECT_EQ(qv_instance_set_colliders(flying.s, nullptr, 0), QV_OK);
  qv_instance_config c = bar.config(1.0 / 60);
  c.free_flight = 0;
  test::Instance grounded(bar.model, c);
  EXPECT_EQ(qv_instance_set_colliders(grounded.s, &good, 1), QV_ERROR_INVALID_ARGUMENT);
}

// The contact slop of the 3 m x 10 cm x 10 cm bar the soft-contact tests lay on the ground: 1e-3 of
// its diagonal (contact.h).
const double kLongBarSlop = 1e-3 * std::sqrt(9 + 2 * 0.01);

// A bar resting on flat ground lies straight: the ground holds every part of its underside, so
// nothing bends it (its own weight only squeezes it, rho g H / E = 1e-3 here). A 3 m bar of 10 cm
// at 1 MPa is so soft that held at its ends alone it would sag metres. With its contacts on the
// rigid shape it sags through the ground where the solve happens not to load it; with soft
// contacts each contact holds the deformed vertex, and it lies straight.
// With the fixed Newton solver too. Under implicit Newmark its steps against soft contacts are the
// minimiser's (quiver.h, soft_contacts): its own rang there (5-9 cm/s after 20 s) and, at one
// Newton iteration (Barbic & James's), flew the bar off to infinity.
TEST(Contact, WithSoftContactsASoftBarLiesStraightOnTheGround) {
  using Case = std::tuple<bool, qv_integrator, qv_solver, int>;  // soft, integrator, solver, Newton iterations (0: default)
  for (const auto& [soft, integrator, solver, iterations] :
       {Case{false, QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_SOLVER_MINIMIZE, 0}, Case{true, QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_SOLVER_MINIMIZE, 0},
        Case{true, QV_INTEGRATOR_BACKWARD_EULER, QV_SOLVER_MINIMIZE, 0}, Case{true, QV_INTEGRATOR_BACKWARD_EULER, QV_SOLVER_NEWTON, 0},
        Case{true, QV_INTEGRATOR_BACKWARD_EULER, QV_SOLVER_NEWTON, 1}, Case{true, QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_SOLVER_NEWTON, 0},
        Case{true, QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_SOLVER_NEWTON, 1}}) {
    Dropped d(1.0 / 60, {ground(0.5, 0)}, {{1.5, 0.05, 0.06}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, 5, {30, 1, 1},
              {3, 0.1, 0.1}, soft, integrator, solver, iterations);
    const double* rest = qv_model_rest_positions(d.bar.model);
    double fastest = 0;  // the fastest any vertex moved in a step of the last second
    Eigen::MatrixXd before;
    for (int i = 0; i < 240; ++i) {
      ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
      const Eigen::MatrixXd now = d.bar.positions(d.inst->s);
      if (i > 180) fastest = std::max(fastest, (now - before).rowwise().norm().maxCoeff() / d.h);
      before = now;
    }
    const Eigen::MatrixXd x = d.bar.positions(d.inst->s);
    double low = INFINITY, high = -INFINITY;
    for (int v = 0; v < d.bar.info.vertex_count; ++v)
      if (rest[3 * v + 2] < 1e-9) low = std::min(low, x(v, 2)), high = std::max(high, x(v, 2));
    std::printf("%s contacts, %s, %s (%d iterations): its underside between z = %.4g and %.4g m; over the last second it moved at most %.2g m/s\n",
                soft ? "soft" : "rigid", qv_integrator_name(integrator), qv_solver_name(solver), iterations, low, high, fastest);
    if (!soft) {
      EXPECT_GT(high - low, 0.1);  // measured: -0.23 to 0.14 m
      continue;
    }
    EXPECT_LT(high - low, 1e-3);  // 0.1 mm
    EXPECT_GT(low, -2 * kLongBarSlop);  // resting contacts sink about a slop
    EXPECT_LT(fastest, 1e-5);
    qv_step_report last;
    qv_instance_last_step(d.inst->s, &last);
    EXPECT_EQ(last.minimized, integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK && solver == QV_SOLVER_NEWTON ? 1 : 0);
  }
}

// Fixed Newton steps on rigid contacts: the same soft 3 m bar dropped on the ground comes to rest
// as under the minimiser. One Newton iteration a step from the last acceleration's guess threw it
// off within 1.5 s (up to 2000 m/s, 130 m high); from the state (fixed_newton.h) it rests.
TEST(Contact, FixedNewtonStepsLayASoftBarToRestOnRigidContacts) {
  using Case = std::tuple<qv_integrator, qv_solver, int>;  // integrator, solver, Newton iterations (0: default)
  for (const auto& [integrator, solver, iterations] :
       {Case{QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_SOLVER_MINIMIZE, 0}, Case{QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_SOLVER_NEWTON, 1},
        Case{QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_SOLVER_NEWTON, 2}, Case{QV_INTEGRATOR_BACKWARD_EULER, QV_SOLVER_NEWTON, 1}}) {
    Dropped d(1.0 / 60, {ground(0.5, 0)}, {{1.5, 0.05, 0.06}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, 5, {30, 1, 1},
              {3, 0.1, 0.1}, false, integrator, solver, iterations);
    double fastest = 0, highest = 0;  // the fastest any vertex moved in a step of the last second; the highest any went
    Eigen::MatrixXd before;
    for (int i = 0; i < 600; ++i) {
      ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET) << "step " << i;
      const Eigen::MatrixXd now = d.bar.positions(d.inst->s);
      if (i > 540) fastest = std::max(fastest, (now - before).rowwise().norm().maxCoeff() / d.h);
      highest = std::max(highest, now.col(2).maxCoeff());
      before = now;
    }
    std::printf("%s, %s (%d iterations): highest vertex %.3g m; over the last second it moved at most %.2g m/s\n",
                qv_integrator_name(integrator), qv_solver_name(solver), iterations, highest, fastest);
    EXPECT_LT(highest, 0.5);   // its ends fly up to 0.25 m as it lands
    EXPECT_LT(fastest, 1e-2);  // measured: at most 7e-4 m/s, as the minimiser's 6e-4
  }
}

// Contacts are found within a margin of what the surfaces cover in the step. With soft contacts a
// vertex moves with the deformation too, which can be far faster than the frame: a 3 m bar lying
// still on the ground, its ends bent 2 cm up and flung down at 3 m/s by its deformation alone,
// crosses the gap in one step (5 cm at 1/60 s). Found only once it was 1 cm deep, it was pushed
// out afterwards; within the margin, the solve stops it at the ground.
TEST(Contact, WithSoftContactsADeformationFlungAtTheGroundStopsAtIt) {
  Dropped d(1.0 / 60, {ground(0.5, 0)}, {{1.5, 0.05, 0.05}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, 5, {30, 1, 1},
            {3, 0.1, 0.1}, true);
  const int r = d.bar.info.r, n = d.bar.info.vertex_count;
  // The basis, a column per state e_j (the frame unrotated), from the positions it gives.
  const std::vector<double> zero(r, 0.0);
  const Eigen::MatrixXd x0 = d.bar.positions(d.inst->s);
  Eigen::MatrixXd U(3 * n, r);
  for (int j = 0; j < r; ++j) {
    std::vector<double> q(r, 0.0);
    q[j] = 1e-3;
    qv_instance_set_state(d.inst->s, q.data(), zero.data(), zero.data());
    const Eigen::MatrixXd x = d.bar.positions(d.inst->s);
    for (int v = 0; v < n; ++v)
      for (int a = 0; a < 3; ++a) U(3 * v + a, j) = (x(v, a) - x0(v, a)) / 1e-3;
  }
  // Ends up by 3 cm, moving down at 3 m/s, the middle still: both as near as the basis comes, by
  // least squares (the ends come 2.1 cm up).
  Eigen::VectorXd up = Eigen::VectorXd::Zero(3 * n), down = Eigen::VectorXd::Zero(3 * n);
  for (int v = 0; v < n; ++v) {
    const double w = std::pow((x0(v, 0) - 1.5) / 1.5, 2);
    up(3 * v + 2) = 0.03 * w, down(3 * v + 2) = -3 * w;
  }
  const auto qr = U.colPivHouseholderQr();
  const Eigen::VectorXd q = qr.solve(up), v = qr.solve(down);
  qv_instance_set_state(d.inst->s, q.data(), v.data(), nullptr);
  const double ends = d.bar.positions(d.inst->s).col(2).maxCoeff() - 0.1;
  double deepest = 0;
  for (int i = 0; i < 30; ++i) {
    ASSERT_NE(qv_instance_step(d.inst->s), QV_STEP_RESET);
    deepest = std::max(deepest, -d.bar.positions(d.inst->s).col(2).minCoeff());
  }
  std::printf("the ends %.3g m up, flung down at 3 m/s: the deepest any vertex went below the ground %.3g m\n", ends,
              deepest);
  EXPECT_GT(ends, 0.015);  // the state is what it says: the ends lifted (2.1 cm: the basis's least squares)
  EXPECT_LT(deepest, 2 * kLongBarSlop);
}

TEST(Contact, SoftContactsNeedFlightAndAnImplicitStep) {
  FreeBar bar;
  qv_instance_config c = bar.config(1.0 / 60);
  c.soft_contacts = 1;
  test::Instance soft(bar.model, c);  // flying, implicit Newmark: fine
  EXPECT_NE(soft.s->modeCompliance, nullptr);
  using Case = std::tuple<int, qv_integrator, qv_elasticity, int>;
  for (const auto& [flying, integrator, elasticity, value] :
       {Case{0, QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_ELASTICITY_STVK, 1}, Case{1, QV_INTEGRATOR_CENTRAL_DIFFERENCES, QV_ELASTICITY_STVK, 1},
        Case{1, QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_ELASTICITY_MODAL_WARPING, 1}, Case{1, QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_ELASTICITY_STVK, 2}}) {
    qv_instance_config bad = c;
    bad.free_flight = flying, bad.integrator = integrator, bad.elasticity = elasticity, bad.soft_contacts = value;
    qv_instance* s = nullptr;
    EXPECT_EQ(qv_instance_create(bar.model, &bad, nullptr, &s), QV_ERROR_INVALID_ARGUMENT);
    if (s) qv_instance_destroy(s);
  }
}

} // namespace
} // namespace quiver
