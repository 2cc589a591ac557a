// A world of flying instances, against mechanics worked by hand: in a stack the ground carries the
// weight of both bars and the lower bar the upper one's; in a collision in space the momenta
// measured from the world positions (consistent mass, central differences) do not change, and a
// perfectly plastic hit leaves both at half the speed; bars falling together do not fall into each
// other when the lowest lands, and bars laid edge on edge stay level; a bar spawned through a cube
// is pushed out without flying off; with soft contacts a soft bar lies straight on a slab; a pile
// of 20 dropped bars comes to rest. Sleeping: a settled pile falls asleep where it rested (as the same pile awake
// rests) and does not move; a bar dropped on a sleeping stack, a platform starting to move, a
// push, new gravity and a ground taken away wake it, and pulling the lowest from a sleeping stack
// lets the one above fall; nothing sleeps while it falls or vibrates, or beside a moving collider.
// Bad use is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "free_bar.h"
#include "runtime_fixture.h"
#include "tests/support/make_collider.h"

namespace quiver {
namespace {

using test::FreeBar;
using test::makeCollider;

constexpr double kG = QV_STANDARD_GRAVITY;

struct World {
  qv_world* w = nullptr;
  std::vector<std::unique_ptr<test::Instance>> bodies;
  std::vector<qv_collider> colliders;
  // Sleeping off unless asked for: most tests here watch contacts at rest.
  explicit World(double friction = 0.5, double restitution = 0, int maxContacts = 4096, double sleepSpeed = 0)
      : World(config(friction, restitution, maxContacts, sleepSpeed)) {}
  explicit World(const qv_world_config& c) { EXPECT_EQ(qv_world_create(&c, nullptr, &w), QV_OK); }
  static qv_world_config config(double friction, double restitution, int maxContacts, double sleepSpeed) {
    qv_world_config c;
    qv_world_config_init(&c);
    c.friction = friction;
    c.restitution = restitution;
    c.max_contacts = maxContacts;
    c.sleep_speed = sleepSpeed;
    return c;
  }
  ~World() { qv_world_destroy(w); }
  qv_instance* add(const FreeBar& bar, double h, const qv_rigid_state& start, bool gravity, bool softContacts = false) {
    qv_instance_config c = bar.config(h);
    c.rayleigh_alpha = 5;
    c.soft_contacts = softContacts ? 1 : 0;
    bodies.push_back(std::make_unique<test::Instance>(bar.model, c));
    qv_instance* s = bodies.back()->s;
    EXPECT_EQ(qv_instance_set_rigid_state(s, &start), QV_OK);
    const double g[3] = {0, 0, gravity ? -kG : 0};
    qv_instance_set_gravity(s, g);
    EXPECT_EQ(qv_world_add(w, s, nullptr), QV_OK);
    return s;
  }
  void setColliders() { EXPECT_EQ(qv_world_set_colliders(w, colliders.data(), static_cast<int>(colliders.size())), QV_OK); }
  std::vector<qv_contact> contacts() const {
    std::vector<qv_contact> out(static_cast<size_t>(qv_world_contacts(w, nullptr, 0)));
    qv_world_contacts(w, out.data(), static_cast<int>(out.size()));
    return out;
  }
};

qv_rigid_state at(double x, double y, double z, double vx = 0) { return {{x, y, z}, {1, 0, 0, 0}, {vx, 0, 0}, {0, 0, 0}}; }

// A job runner that runs a world's jobs backwards on the calling thread (qv_world_set_jobs).
void runBackwards(void*, qv_job_function job, void* data, int count) {
  for (int i = count - 1; i >= 0; --i) job(data, i);
}

TEST(World, InAStackTheGroundCarriesBothAndTheLowerBarTheUpper) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  World world;
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  world.add(bar, h, at(0.3, 0.05, 0.052), true);  // lower (index 0)
  world.add(bar, h, at(0.3, 0.05, 0.155), true);  // upper, 3 mm above it
  for (int i = 0; i < 180; ++i) ASSERT_EQ(qv_world_step(world.w), 0);
  double ground = 0, between = 0;
  for (int i = 0; i < 60; ++i) {
    ASSERT_EQ(qv_world_step(world.w), 0);
    for (const qv_contact& c : world.contacts()) {
      const double fz = c.impulse[2] / h / 60;
      if (c.other < 0) ground += fz;
      if (c.instance == 1 && c.other == 0) between += fz;  // on the upper, from the lower
      if (c.instance == 0 && c.other == 1) between -= fz;  // on the lower, from the upper: the opposite
    }
  }
  const double weight = bar.info.total_mass * kG;
  qv_rigid_state upper;
  qv_instance_get_rigid_state(world.bodies[1]->s, &upper);
  std::printf("stack of two: the ground carries %.5g N (weight of both %.5g N), the lower bar %.5g N (%.5g N); "
              "upper centre at %.4f m (0.15)\n", ground, 2 * weight, between, weight, upper.position[2]);
  EXPECT_NEAR(ground, 2 * weight, 1e-3 * weight);
  EXPECT_NEAR(between, weight, 1e-3 * weight);
  EXPECT_NEAR(upper.position[2], 0.15, 6e-3);
}

// Three bars one above the other, `gap` apart, dropped from `drop`.
struct ThreeBars {
  double landing = 0, deepest = 0, tilt = 0;  // m/s; the rigid shapes' overlap, m; the most tilted at the end, rad
};
enum class Laid { Crosswise, EdgeOnEdge };

// Crosswise (each turned a quarter about z from the one below) or edge on edge (aligned). The
// overlap is of the rigid shapes the frames carry: crosswise they touch about their centres, edge
// on edge along their whole faces, so it is the bars' height less the distance of the centres
// while they stay level; the tilt at the end says whether they do.
ThreeBars dropThreeBars(Laid laid, double gap, double drop) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60, height = 0.1;
  World world;
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  for (int k = 0; k < 3; ++k) {
    qv_rigid_state s = at(0.3, 0.05, drop + height / 2 + k * (height + gap));
    if (laid == Laid::Crosswise) s.orientation[0] = std::cos(k * M_PI / 4), s.orientation[3] = std::sin(k * M_PI / 4);
    world.add(bar, h, s, true);
  }
  ThreeBars out;
  for (int i = 0; i < 120; ++i) {
    EXPECT_EQ(qv_world_step(world.w), 0);
    qv_rigid_state s[3];
    for (int k = 0; k < 3; ++k) {
      qv_instance_get_rigid_state(world.bodies[k]->s, &s[k]);
      out.landing = std::max(out.landing, -s[k].linear_velocity[2]);
      const Eigen::Quaterniond turn(s[k].orientation[0], s[k].orientation[1], s[k].orientation[2], s[k].orientation[3]);
      if (i == 119) out.tilt = std::max(out.tilt, std::acos(std::min(1.0, (turn * Eigen::Vector3d::UnitZ()).z())));
    }
    out.deepest = std::max({out.deepest, height / 2 - s[0].position[2], height - (s[1].position[2] - s[0].position[2]),
                            height - (s[2].position[2] - s[1].position[2])});
  }
  return out;
}

// Falling together 3 cm apart, the lowest stopped by the ground at 4 m/s (6.7 cm in a step). Their
// relative speed at the step's start is zero, so margins from it alone saw no contact between them,
// and each fell into the one stopped below it (24.6 mm, measured).
TEST(World, BarsFallingTogetherDoNotFallIntoEachOtherWhenTheLowestLands) {
  const double h = 1.0 / 60, gap = 0.03;
  const ThreeBars three = dropThreeBars(Laid::Crosswise, gap, 0.8);
  std::printf("three bars crosswise falling 3 cm apart, landing at %.2f m/s: deepest overlap of their rigid shapes %.2f mm\n",
              three.landing, 1e3 * three.deepest);
  EXPECT_GT(three.landing * h, gap + 0.03);  // each step covers the gap, and more
  EXPECT_LT(three.deepest, 0.006);
}

// Laid edge on edge, each rim vertex lies on the rim of the other's face, nearest the side face
// below it: its sideways normals rolled them over, and they rested so, 13 and 23 degrees, 1.2 cm
// into each other (measured), dropped from 5 mm as from 0.8 m.
TEST(World, BarsLaidEdgeOnEdgeStayLevel) {
  for (const double drop : {0.0, 0.8}) {
    const ThreeBars three = dropThreeBars(Laid::EdgeOnEdge, 0.005, drop);
    std::printf("three bars edge on edge, landing at %.2f m/s: tilted %.3f degrees at the end, deepest overlap %.2f mm\n",
                three.landing, three.tilt * 180 / M_PI, 1e3 * three.deepest);
    EXPECT_LT(three.tilt, 0.5 * M_PI / 180);
    EXPECT_LT(three.deepest, 0.004);
  }
}

// Linear and angular momentum (about the origin) of all bodies from their world positions at steps
// n - 1 and n + 1 around step n.
void measuredMomentum(const FreeBar& bar, World& world, Eigen::Vector3d& P, Eigen::Vector3d& L, double h) {
  std::vector<Eigen::MatrixXd> before, now;
  for (auto& b : world.bodies) before.push_back(bar.positions(b->s));
  qv_world_step(world.w);
  for (auto& b : world.bodies) now.push_back(bar.positions(b->s));
  qv_world_step(world.w);
  P.setZero();
  L.setZero();
  for (size_t i = 0; i < world.bodies.size(); ++i) {
    const Eigen::MatrixXd after = bar.positions(world.bodies[i]->s);
    Eigen::Vector3d p, l;
    bar.momentum(now[i], (after - before[i]) / (2 * h), p, l);
    P += p;
    L += l;
  }
}

TEST(World, ACollisionInSpaceKeepsTheMomentaAndAPlasticHitSharesTheSpeed) {
  FreeBar bar(16, {6, 1, 1});
  const double h = 1.0 / 240, speed = 1;
  for (const double restitution : {0.0, 1.0}) {
    World world(0.5, restitution);
    // End to end along x, the left one moving at 1 m/s, off-centre by 2 cm so that they also turn.
    world.add(bar, h, at(0.3, 0.05, 0.05, speed), false);
    world.add(bar, h, at(0.92, 0.05, 0.07), false);
    Eigen::Vector3d P0, L0, P1, L1;
    measuredMomentum(bar, world, P0, L0, h);
    int touching = 0;
    for (int i = 0; i < 120; ++i) {
      ASSERT_EQ(qv_world_step(world.w), 0);
      touching += !world.contacts().empty();
    }
    measuredMomentum(bar, world, P1, L1, h);
    qv_rigid_state a, b;
    qv_instance_get_rigid_state(world.bodies[0]->s, &a);
    qv_instance_get_rigid_state(world.bodies[1]->s, &b);
    const double p = bar.info.total_mass * speed;
    std::printf("restitution %.0f: contact in %d steps; momentum change %.2e of m v, angular %.2e (kg m^2/s); "
                "velocities after %.4f and %.4f m/s\n", restitution, touching, (P1 - P0).norm() / p, (L1 - L0).norm(),
                a.linear_velocity[0], b.linear_velocity[0]);
    EXPECT_GT(touching, 0);
    EXPECT_LT((P1 - P0).norm(), 1e-3 * p);
    EXPECT_LT((L1 - L0).norm(), 1e-3 * p * 0.6);
    if (restitution == 0) {
      EXPECT_NEAR(a.linear_velocity[0], speed / 2, 0.05 * speed);
      EXPECT_NEAR(b.linear_velocity[0], speed / 2, 0.05 * speed);
    } else {
      EXPECT_LT(a.linear_velocity[0], 0.3 * speed);  // most of the speed handed on
      EXPECT_GT(b.linear_velocity[0], 0.7 * speed);
    }
  }
}

// Twenty bars dropped into a bin 0.8 x 0.8 m (the ground and four walls) in five layers of four,
// each layer crosswise to the one below, a little turned and shaken.
void dropTwentyIntoABin(World& world, const FreeBar& bar, double h) {
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0),
                     makeCollider(QV_COLLIDER_PLANE, {1, 0, 0, -0.4, 0, 0, 0, 0}, 0.5, 0),
                     makeCollider(QV_COLLIDER_PLANE, {-1, 0, 0, -0.4, 0, 0, 0, 0}, 0.5, 0),
                     makeCollider(QV_COLLIDER_PLANE, {0, 1, 0, -0.4, 0, 0, 0, 0}, 0.5, 0),
                     makeCollider(QV_COLLIDER_PLANE, {0, -1, 0, -0.4, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int layer = 0; layer < 5; ++layer)
    for (int k = 0; k < 4; ++k) {
      const double across = -0.24 + 0.16 * k, z = 0.15 + 0.2 * layer;
      const double yaw = (layer % 2 ? M_PI / 2 : 0) + jitter(rng), tilt = jitter(rng);
      qv_rigid_state s = layer % 2 ? at(across, jitter(rng), z) : at(jitter(rng), across, z);
      s.orientation[0] = std::cos(yaw / 2) * std::cos(tilt / 2);
      s.orientation[1] = std::cos(yaw / 2) * std::sin(tilt / 2);
      s.orientation[2] = std::sin(yaw / 2) * std::sin(tilt / 2);
      s.orientation[3] = std::sin(yaw / 2) * std::cos(tilt / 2);
      world.add(bar, h, s, true);
    }
}

TEST(World, APileOfTwentyDroppedBarsComesToRest) {
  FreeBar bar(16, {6, 1, 1});
  const double h = 1.0 / 60;
  World world(0.5, 0, 4096);
  dropTwentyIntoABin(world, bar, h);
  double deepest = 0, fastest = 0, spin = 0;
  int resets = 0, maxContacts = 0;
  for (int i = 0; i < 360; ++i) {  // 6 s
    resets += qv_world_step(world.w);
    const std::vector<qv_contact> contacts = world.contacts();
    maxContacts = std::max(maxContacts, static_cast<int>(contacts.size()));
    if (i >= 300)
      for (const qv_contact& c : contacts) deepest = std::max(deepest, -c.depth);
  }
  double highest = 0, lowest = INFINITY;
  for (auto& b : world.bodies) {
    qv_rigid_state s;
    qv_instance_get_rigid_state(b->s, &s);
    fastest = std::max(fastest, std::sqrt(s.linear_velocity[0] * s.linear_velocity[0] + s.linear_velocity[1] * s.linear_velocity[1] +
                                          s.linear_velocity[2] * s.linear_velocity[2]));
    spin = std::max(spin, std::sqrt(s.angular_velocity[0] * s.angular_velocity[0] + s.angular_velocity[1] * s.angular_velocity[1] +
                                    s.angular_velocity[2] * s.angular_velocity[2]));
    highest = std::max(highest, s.position[2]);
    lowest = std::min(lowest, s.position[2]);
    for (int a = 0; a < 2; ++a) EXPECT_LT(std::fabs(s.position[a]), 0.4);  // in the bin
  }
  std::printf("pile of 20 after 6 s: fastest %.3g m/s, fastest spin %.3g rad/s, centres from %.3f to %.3f m high; "
              "deepest penetration in the last second %.3g m; at most %d contacts; %d resets\n", fastest, spin, lowest,
              highest, deepest, maxContacts, resets);
  EXPECT_EQ(resets, 0);
  EXPECT_LT(fastest, 1e-3);  // warm-started impulses: 5 mm/s of jitter without (measured)
  EXPECT_LT(spin, 0.01);
  EXPECT_GT(lowest, 0.04);   // none sunk through the ground
  EXPECT_GT(highest, 0.25);  // a pile, not a single layer
  EXPECT_LT(deepest, 0.008);
}

constexpr double kSleepSpeed = 0.02;  // m/s

Eigen::Vector3d centre(qv_instance* s) {
  qv_rigid_state state;
  qv_instance_get_rigid_state(s, &state);
  return {state.position[0], state.position[1], state.position[2]};
}

int asleep(const World& world) {
  int n = 0;
  for (const auto& b : world.bodies) n += qv_instance_asleep(b->s);
  return n;
}

// Whether `s` is asleep after some step of the next `steps`.
bool sleepsWithin(World& world, qv_instance* s, int steps) {
  bool slept = false;
  for (int i = 0; i < steps; ++i) {
    EXPECT_EQ(qv_world_step(world.w), 0);
    slept |= qv_instance_asleep(s) != 0;
  }
  return slept;
}

// The same pile twice, sleeping and awake. Asleep, it must rest where the awake one rests (a
// group put to sleep while still settling would stay where it was caught), not move at all, and
// have no contacts.
TEST(World, ASettledPileFallsAsleepWhereItRestsAndStaysThere) {
  FreeBar bar(16, {6, 1, 1});
  const double h = 1.0 / 60;
  World sleeping(0.5, 0, 4096, kSleepSpeed), awake(0.5, 0, 4096, 0);
  dropTwentyIntoABin(sleeping, bar, h);
  dropTwentyIntoABin(awake, bar, h);
  int allAsleepAt = -1;
  for (int i = 0; i < 480 && allAsleepAt < 0; ++i) {  // 8 s at most
    ASSERT_EQ(qv_world_step(sleeping.w), 0);
    if (asleep(sleeping) == 20) allAsleepAt = i;
  }
  ASSERT_GE(allAsleepAt, 0) << asleep(sleeping) << " of 20 asleep after 8 s";
  for (int i = 0; i <= allAsleepAt + 120; ++i) ASSERT_EQ(qv_world_step(awake.w), 0);  // 2 s longer
  std::vector<std::vector<float>> before;
  for (auto& b : sleeping.bodies) {
    before.emplace_back(3 * bar.info.vertex_count);
    qv_instance_positions(b->s, before.back().data());
  }
  for (int i = 0; i < 120; ++i) ASSERT_EQ(qv_world_step(sleeping.w), 0);
  double apart = 0;
  for (size_t k = 0; k < sleeping.bodies.size(); ++k) {
    std::vector<float> now(3 * bar.info.vertex_count);
    qv_instance_positions(sleeping.bodies[k]->s, now.data());
    EXPECT_EQ(now, before[k]) << "body " << k << " moved asleep";
    apart = std::max(apart, (centre(sleeping.bodies[k]->s) - centre(awake.bodies[k]->s)).norm());
  }
  std::printf("pile of 20: all asleep after %.2f s; 2 s later each centre within %.3g mm of the same pile kept awake\n",
              (allAsleepAt + 1) * h, 1e3 * apart);
  EXPECT_EQ(asleep(sleeping), 20);
  EXPECT_TRUE(sleeping.contacts().empty());
  EXPECT_LT(apart, 0.002);
}

// Everything of a world that a rewind must repeat: each instance's positions and whether it sleeps,
// and the world's contacts, as bytes.
std::vector<char> sceneOf(const World& world, const FreeBar& bar) {
  std::vector<char> out;
  const auto append = [&](const void* p, size_t n) { out.insert(out.end(), static_cast<const char*>(p), static_cast<const char*>(p) + n); };
  for (const auto& b : world.bodies) {
    std::vector<float> x(3 * bar.info.vertex_count);
    qv_instance_positions(b->s, x.data());
    append(x.data(), x.size() * sizeof(float));
    const int sleeps = qv_instance_asleep(b->s);
    append(&sleeps, sizeof sleeps);
  }
  const std::vector<qv_contact> contacts = world.contacts();
  append(contacts.data(), contacts.size() * sizeof(qv_contact));
  return out;
}

// A world's snapshot rewinds a pile of twenty bars settling and falling asleep bit for bit: their
// positions, their sleep and their contacts; the same snapshot with its contacts left out (cold
// starts) ends elsewhere. Restored and saved again, it is the same bytes. One another world could
// not have saved is refused, the world unchanged.
TEST(World, ASnapshotRewindsAPileSettlingAndFallingAsleepBitForBit) {
  FreeBar bar(16, {6, 1, 1});
  const double h = 1.0 / 60;
  World world(0.5, 0, 4096, kSleepSpeed);
  dropTwentyIntoABin(world, bar, h);
  // Where a snapshot's parts are (quiver::rt::kContactRecord = 20 doubles a contact, 64 in an instance's).
  const size_t state = qv_instance_snapshot_size(world.bodies[0]->s) / sizeof(double) - (1 + 20 * 64);
  const size_t contactsAt = 1 + 20 * (3 + state);
  for (int i = 0; i < 150; ++i) ASSERT_EQ(qv_world_step(world.w), 0);
  ASSERT_EQ(asleep(world), 0);
  std::vector<double> snapshot(qv_world_snapshot_size(world.w) / sizeof(double));
  const size_t used = qv_world_save_snapshot(world.w, snapshot.data());
  const size_t held = world.contacts().size();
  ASSERT_GT(held, 40u);
  ASSERT_EQ(snapshot[contactsAt], static_cast<double>(held));
  const std::vector<char> saved = sceneOf(world, bar);
  const auto run = [&](const std::vector<double>& from) {
    EXPECT_EQ(qv_world_restore_snapshot(world.w, from.data(), used), QV_OK);
    for (int i = 0; i < 240; ++i) EXPECT_EQ(qv_world_step(world.w), 0);
    return sceneOf(world, bar);
  };
  const std::vector<char> first = run(snapshot);
  ASSERT_EQ(asleep(world), 20) << "not all fell asleep in the steps rewound";
  ASSERT_EQ(qv_world_restore_snapshot(world.w, snapshot.data(), used), QV_OK);
  EXPECT_TRUE(sceneOf(world, bar) == saved);
  EXPECT_TRUE(run(snapshot) == first);
  std::printf("pile of 20: a world snapshot of %zu bytes (at most %zu) with %zu contacts rewound 4 s in which all fell asleep\n",
              used, snapshot.size() * sizeof(double), held);
  std::vector<double> cold = snapshot;
  cold[contactsAt] = 0;
  EXPECT_FALSE(run(cold) == first);
  // Saved again once restored, the same bytes (the still times and sleep groups too); the pile
  // asleep (after the cold run), restored over an awake one, sleeps again.
  std::vector<double> again(snapshot.size()), sleeping(snapshot.size());
  ASSERT_EQ(asleep(world), 20) << "the cold run did not fall asleep";
  const size_t asleepUsed = qv_world_save_snapshot(world.w, sleeping.data());
  ASSERT_EQ(qv_world_restore_snapshot(world.w, snapshot.data(), used), QV_OK);
  ASSERT_EQ(qv_world_save_snapshot(world.w, again.data()), used);
  EXPECT_TRUE(std::equal(snapshot.begin(), snapshot.begin() + used / sizeof(double), again.begin()));
  ASSERT_EQ(asleep(world), 0);
  ASSERT_EQ(qv_world_restore_snapshot(world.w, sleeping.data(), asleepUsed), QV_OK);
  EXPECT_EQ(asleep(world), 20);
  // Refused: cut short, a sleep group that is no instance's, a contact on a vertex the model does
  // not have, contacts out of order, a negative normal impulse, a world of another size.
  const std::vector<char> now = sceneOf(world, bar);
  EXPECT_EQ(qv_world_restore_snapshot(world.w, snapshot.data(), used - sizeof(double)), QV_ERROR_INVALID_ARGUMENT);
  const auto refused = [&](size_t at, double value) {
    std::vector<double> spoiled = snapshot;
    spoiled[at] = value;
    return qv_world_restore_snapshot(world.w, spoiled.data(), used) == QV_ERROR_INVALID_ARGUMENT;
  };
  EXPECT_TRUE(refused(1 + 2, 20));  // the first instance's sleep group
  EXPECT_TRUE(refused(contactsAt + 1 + 3, bar.info.vertex_count));
  EXPECT_TRUE(refused(contactsAt + 1, 19));
  EXPECT_TRUE(refused(contactsAt + 1 + 11, -1));
  EXPECT_TRUE(sceneOf(world, bar) == now);
  World fewer(0.5, 0, 4096, kSleepSpeed);
  fewer.add(bar, h, at(0, 0, 1), true);
  EXPECT_EQ(qv_world_restore_snapshot(fewer.w, snapshot.data(), used), QV_ERROR_INVALID_ARGUMENT);
}

// Two bars crosswise on the ground (instances 0 and 1), stepped until both sleep.
void laySleepingStack(World& world, const FreeBar& bar, double h) {
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  qv_rigid_state turned = at(0.3, 0.05, 0.155);
  turned.orientation[0] = turned.orientation[3] = std::sqrt(0.5);
  world.add(bar, h, at(0.3, 0.05, 0.052), true);
  world.add(bar, h, turned, true);
  for (int i = 0; i < 120 && asleep(world) < 2; ++i) ASSERT_EQ(qv_world_step(world.w), 0);
  ASSERT_EQ(asleep(world), 2);
}

// laySleepingStack(), and a third bar above it at `height` (instance 2), falling.
void laySleepingStackUnderABar(World& world, const FreeBar& bar, double h, double height) {
  laySleepingStack(world, bar, h);
  if (!::testing::Test::HasFatalFailure()) world.add(bar, h, at(0.3, 0.05, height), true);
}

// A third bar dropped from 0.3 m above a sleeping stack must wake it and land on it, not pass
// through the sleepers (their contacts are not sought while they sleep).
TEST(World, ABarDroppedOnASleepingStackWakesItAndLandsOnIt) {
  FreeBar bar(16, {12, 2, 2});
  World world(0.5, 0, 4096, kSleepSpeed);
  laySleepingStackUnderABar(world, bar, 1.0 / 60, 0.55);
  ASSERT_FALSE(HasFatalFailure());
  bool woke = false;
  for (int i = 0; i < 180; ++i) {
    ASSERT_EQ(qv_world_step(world.w), 0);
    woke |= asleep(world) == 0 && centre(world.bodies[2]->s).z() < 0.35;
  }
  const double top = centre(world.bodies[2]->s).z();
  std::printf("a bar dropped on a sleeping stack of two: it woke: %s; the dropped bar rests at %.4f m (0.25)\n",
              woke ? "yes" : "no", top);
  EXPECT_TRUE(woke);
  EXPECT_NEAR(top, 0.25, 0.01);
}

// A snapshot taken while a stack sleeps and a bar falls onto it rewinds bit for bit, though the
// sleepers moved since: woken by the bar, and one given a fast spin by the caller. A sleeper is not
// stepped, yet its spin decides who can reach it, so restoring must bring it up to date with the
// restored state (it was that of the last motion: the stack then woke at once).
TEST(World, ASnapshotWithSleepersRewindsBitForBitAfterTheyMoved) {
  FreeBar bar(16, {12, 2, 2});
  World world(0.5, 0, 4096, kSleepSpeed);
  laySleepingStackUnderABar(world, bar, 1.0 / 60, 1.2);  // beyond reach of the stack's bounding spheres at first
  ASSERT_FALSE(HasFatalFailure());
  std::vector<double> snapshot(qv_world_snapshot_size(world.w) / sizeof(double));
  const size_t used = qv_world_save_snapshot(world.w, snapshot.data());
  const auto landing = [&] {
    for (int i = 0; i < 90; ++i) EXPECT_EQ(qv_world_step(world.w), 0);
    return sceneOf(world, bar);
  };
  const std::vector<char> first = landing();
  ASSERT_LT(asleep(world), 2) << "the stack never woke";
  const qv_rigid_state spun = {{0.3, 0.05, 0.3}, {1, 0, 0, 0}, {0, 0, 0}, {200, 0, 50}};
  ASSERT_EQ(qv_instance_set_rigid_state(world.bodies[0]->s, &spun), QV_OK);
  ASSERT_EQ(qv_world_step(world.w), 0);
  ASSERT_EQ(qv_world_restore_snapshot(world.w, snapshot.data(), used), QV_OK);
  EXPECT_EQ(asleep(world), 2);
  EXPECT_TRUE(landing() == first);
}

// A bar asleep on a box (a platform, the caller moving it with a velocity) wakes when the platform
// starts to move and rides it by friction; it sleeps again once the platform stops.
TEST(World, ASleepingBarWakesWhenItsPlatformMovesAndRidesIt) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60, speed = 0.3;
  World world(0.8, 0, 4096, kSleepSpeed);
  world.colliders = {makeCollider(QV_COLLIDER_BOX, {0.3, 0.05, -0.05, 1, 1, 0.05, 0, 0}, 0.8, 0)};
  world.setColliders();
  qv_instance* s = world.add(bar, h, at(0.3, 0.05, 0.052), true);
  for (int i = 0; i < 120 && !qv_instance_asleep(s); ++i) ASSERT_EQ(qv_world_step(world.w), 0);
  ASSERT_TRUE(qv_instance_asleep(s));
  const double x0 = centre(s).x();
  // 1 s along x, accelerating gently (at most 0.94 m/s^2, within friction's 7.8) to `speed` and back.
  for (int i = 0; i < 60; ++i) {
    const double t = (i + 0.5) * h, v = speed * std::sin(M_PI * t);
    world.colliders[0].velocity[0] = v;
    world.colliders[0].data[0] += v * h;
    ASSERT_EQ(qv_world_step(world.w), 0);
  }
  const double carried = world.colliders[0].data[0] - 0.3, moved = centre(s).x() - x0;
  world.colliders[0].velocity[0] = 0;
  const bool sleepsAgain = sleepsWithin(world, s, 120);
  std::printf("platform moved %.4f m; the bar on it, asleep before, %.4f m; asleep again after it stopped: %s\n", carried,
              moved, sleepsAgain ? "yes" : "no");
  EXPECT_NEAR(moved, carried, 0.05 * carried);
  EXPECT_TRUE(sleepsAgain);
}

// Whatever the caller does to a sleeping bar wakes it: a push, gravity turned up, the ground taken
// away. The same gravity again, or a zero force, does not.
TEST(World, APushNewGravityOrAGroundTakenAwayWakesASleeper) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  World world(0.5, 0, 4096, kSleepSpeed);
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  qv_instance* s = world.add(bar, h, at(0.3, 0.05, 0.052), true);
  // Within 6 s: kicked below, it tumbles at 15 rad/s, lands and rocks to sleep in 4.3 s (3.7 s
  // when the frame's turn was the fixed-point midpoint, which lost some of the spin's energy).
  const auto settle = [&] {
    for (int i = 0; i < 360 && !qv_instance_asleep(s); ++i) ASSERT_EQ(qv_world_step(world.w), 0);
    ASSERT_TRUE(qv_instance_asleep(s));
  };
  settle();
  const double zero[3] = {0, 0, 0}, g[3] = {0, 0, -kG}, up[3] = {0, 0, kG}, lift[3] = {0, 0, 500};
  EXPECT_EQ(qv_instance_add_vertex_force(s, 0, zero), QV_OK);
  qv_instance_set_gravity(s, g);
  qv_world_step(world.w);
  EXPECT_TRUE(qv_instance_asleep(s)) << "a zero force or the same gravity woke it";
  const double z0 = centre(s).z();
  EXPECT_EQ(qv_instance_add_vertex_force(s, 0, lift), QV_OK);  // 500 N at a corner for a step: 8 N s on 6 kg
  qv_world_step(world.w);
  EXPECT_FALSE(qv_instance_asleep(s));
  EXPECT_GT(centre(s).z(), z0);  // its corner rose
  settle();
  qv_instance_set_gravity(s, up);
  for (int i = 0; i < 30; ++i) qv_world_step(world.w);
  EXPECT_GT(centre(s).z(), z0 + 0.1) << "gravity turned up did not lift it";
  qv_instance_set_gravity(s, g);
  for (int i = 0; i < 120; ++i) qv_world_step(world.w);  // back on the ground
  settle();
  world.colliders.clear();
  world.setColliders();
  for (int i = 0; i < 30; ++i) qv_world_step(world.w);
  std::printf("pushed, gravity up and the ground taken away, the sleeping bar moved; fell to %.3f m\n", centre(s).z());
  EXPECT_LT(centre(s).z(), z0 - 0.5 * kG * 0.25 * 0.9);  // half a second of free fall
}

// The caller moves the lowest of a sleeping stack of two away: the one above must fall, not hang
// asleep in the air (moving it wakes only it, and it is no longer near the one above).
TEST(World, TheLowestPulledFromASleepingStackLetsTheOneAboveFall) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  World world(0.5, 0, 4096, kSleepSpeed);
  laySleepingStack(world, bar, h);
  ASSERT_FALSE(HasFatalFailure());
  qv_instance *lower = world.bodies[0]->s, *upper = world.bodies[1]->s;
  const qv_rigid_state aside = at(3, 0.05, 0.052);
  EXPECT_EQ(qv_instance_set_rigid_state(lower, &aside), QV_OK);
  for (int i = 0; i < 60; ++i) ASSERT_EQ(qv_world_step(world.w), 0);
  std::printf("the lowest of a sleeping stack pulled away: the upper fell from 0.15 to %.4f m\n", centre(upper).z());
  EXPECT_NEAR(centre(upper).z(), 0.05, 0.005);  // on the ground
}

// A game despawns the lowest of a sleeping stack (qv_world_remove), asleep or just woken by the
// game (moved aside, which wakes only it until the next step spreads the wake): the one above wakes
// at once and falls to the ground, while a bar asleep elsewhere sleeps on where it was; the
// instances after the removed one move down an index, as the contacts name them; the removed one
// is awake, steps alone and can be added again.
TEST(World, TheLowestRemovedFromASleepingStackLetsTheOneAboveFallAndTheRestSleepOn) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  for (const bool movedFirst : {false, true}) {
    World world(0.5, 0, 4096, kSleepSpeed);
    laySleepingStack(world, bar, h);
    ASSERT_FALSE(HasFatalFailure());
    qv_instance* apart = world.add(bar, h, at(3, 0.05, 0.052), true);
    ASSERT_TRUE(sleepsWithin(world, apart, 120));
    ASSERT_EQ(asleep(world), 3);
    qv_instance *lower = world.bodies[0]->s, *upper = world.bodies[1]->s;
    const Eigen::MatrixXd apartBefore = bar.positions(apart);
    if (movedFirst) {
      const qv_rigid_state aside = at(0.3, 3, 0.052);
      ASSERT_EQ(qv_instance_set_rigid_state(lower, &aside), QV_OK);
      ASSERT_EQ(qv_instance_asleep(upper), 1);
    }
    ASSERT_EQ(qv_world_remove(world.w, lower), QV_OK);
    EXPECT_EQ(qv_instance_asleep(lower), 0);
    EXPECT_EQ(qv_instance_asleep(upper), 0);  // it slept with the lower
    EXPECT_EQ(qv_instance_asleep(apart), 1);
    EXPECT_EQ(qv_world_remove(world.w, lower), QV_ERROR_INVALID_ARGUMENT);  // no longer in
    int named = 0;
    for (int i = 0; i < 60; ++i) {
      ASSERT_EQ(qv_world_step(world.w), 0);
      for (const qv_contact& c : world.contacts()) {
        EXPECT_EQ(c.instance, 0);  // the upper, now the first; the bar apart sleeps without contacts
        EXPECT_EQ(c.other, -1);    // on the ground
        ++named;
      }
    }
    std::printf("the lowest of a sleeping stack removed%s: the upper fell from 0.15 to %.4f m (%d contacts on the ground in "
                "a second); the bar apart asleep: %d\n", movedFirst ? " after the game moved it" : "", centre(upper).z(), named,
                qv_instance_asleep(apart));
    EXPECT_NEAR(centre(upper).z(), 0.05, 0.005);
    EXPECT_GT(named, 0);
    EXPECT_EQ(qv_instance_asleep(apart), 1);
    EXPECT_EQ(bar.positions(apart), apartBefore);
    // Its sleep group renumbered with it (a group's id is an index: one past the last is refused).
    std::vector<double> snapshot(qv_world_snapshot_size(world.w) / sizeof(double));
    const size_t used = qv_world_save_snapshot(world.w, snapshot.data());
    EXPECT_EQ(qv_world_restore_snapshot(world.w, snapshot.data(), used), QV_OK);
    EXPECT_NE(qv_instance_step(lower), QV_STEP_RESET);  // alone now, falling with no ground of its own
    int index = -1;
    EXPECT_EQ(qv_world_add(world.w, lower, &index), QV_OK);
    EXPECT_EQ(index, 2);
  }
}

// Removing a body leaves the others as they would be had it never been in the world: two bars
// settling in a stack and one coming to rest apart, beside a bar thrown tumbling away (the first
// instance, removed after 40 steps, so that every contact between the others is renumbered), end
// bit for bit where the same three end in a world of their own, their contacts carried on through
// the removal (restarting them cold moved them in the last bits).
TEST(World, RemovingABodyLeavesTheOthersAsIfItHadNeverBeen) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  World four, three;
  qv_rigid_state turned = at(0.3, 0.05, 0.16);
  turned.orientation[0] = turned.orientation[3] = std::sqrt(0.5);
  qv_rigid_state thrown = at(3, 0, 0.3, 4);
  thrown.angular_velocity[0] = 6;
  qv_instance* gone = nullptr;
  for (World* w : {&four, &three}) {
    w->colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
    w->setColliders();
    if (w == &four) gone = w->add(bar, h, thrown, true);
    w->add(bar, h, at(0.3, 0.05, 0.055), true);
    w->add(bar, h, turned, true);
    w->add(bar, h, at(-3, 0.05, 0.07), true);
  }
  const auto same = [&] {
    for (int k = 0; k < 3; ++k)
      if (bar.positions(four.bodies[k + 1]->s) != bar.positions(three.bodies[k]->s)) return false;
    return true;
  };
  for (int i = 0; i < 40; ++i) {
    ASSERT_EQ(qv_world_step(four.w), 0);
    ASSERT_EQ(qv_world_step(three.w), 0);
  }
  ASSERT_TRUE(same()) << "the thrown bar changed the others before its removal";
  ASSERT_EQ(qv_world_remove(four.w, gone), QV_OK);
  int between = 0;  // contacts of the stack's bars with each other, renumbered on both sides
  for (const qv_contact& c : four.contacts()) between += c.other >= 0;
  ASSERT_GT(between, 0);
  for (int i = 0; i < 60; ++i) {
    ASSERT_EQ(qv_world_step(four.w), 0);
    ASSERT_EQ(qv_world_step(three.w), 0);
  }
  EXPECT_TRUE(same());
  EXPECT_EQ(four.contacts().size(), three.contacts().size());
}

// Asleep after a single still step (sleep_time 0), but never while falling.
TEST(World, WithNoSleepTimeABarSleepsOnlyOnceItIsStill) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  qv_world_config c = World::config(0.5, 0, 4096, kSleepSpeed);
  c.sleep_time = 0;
  World world(c);
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  qv_instance* s = world.add(bar, h, at(0.3, 0.05, 0.5), true);
  int fellAsleepAt = -1;
  for (int i = 0; i < 120 && fellAsleepAt < 0; ++i) {
    ASSERT_EQ(qv_world_step(world.w), 0);
    if (qv_instance_asleep(s)) fellAsleepAt = i;
  }
  std::printf("with no sleep time, a bar dropped from 0.45 m fell asleep after %.3f s at %.4f m\n", (fellAsleepAt + 1) * h,
              centre(s).z());
  ASSERT_GE(fellAsleepAt, 0);
  EXPECT_NEAR(centre(s).z(), 0.05, 0.005);  // on the ground, not in the air
}

// The contact solve sweeps each island (the bodies its contacts join) until its impulses settle
// (contact.cpp, kConverged): a bar coming to rest on the ground beside another sliding and tumbling
// 3 m away ends where the same bar alone in a world ends, bit for bit, though the other island
// keeps sweeping after the bar's has settled. Solved as one (all sweeping while any moved) it did
// not (the last bits of its pose differed).
TEST(World, ABarComingToRestIsSolvedAsIfAloneBesideABusyOne) {
  FreeBar bar;
  const double h = 1.0 / 60;
  World pair, alone;
  for (World* w : {&pair, &alone}) {
    w->colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
    w->setColliders();
    w->add(bar, h, at(0, 0, 0.07), true);
  }
  qv_rigid_state thrown = at(3, 0, 0.3, 4);
  thrown.angular_velocity[0] = 6;
  pair.add(bar, h, thrown, true);
  for (int i = 0; i < 240; ++i) {
    ASSERT_EQ(qv_world_step(pair.w), 0);
    ASSERT_EQ(qv_world_step(alone.w), 0);
  }
  EXPECT_EQ(bar.positions(pair.bodies[0]->s), bar.positions(alone.bodies[0]->s));
  qv_rigid_state busy;
  qv_instance_get_rigid_state(pair.bodies[1]->s, &busy);
  EXPECT_GT(busy.position[0], 4);  // it slid on
}

// A world of one steps its bar as the bar steps alone, bit for bit, while it lands tumbling, bounces
// and comes to rest: the same contacts, and the same turns settled (qv_instance::takeOutTurnExcess,
// which leaves a body with contacts in reach alone; until 2026-11-29 it read the instance's own
// contacts, which a world member never holds, and settled the world's bars in contact: the two
// ended 1.6e-5 m apart).
TEST(World, AWorldOfOneStepsItsBarAsTheBarStepsAlone) {
  FreeBar bar;
  const double h = 1.0 / 60;
  const qv_collider ground = makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0.3);
  qv_rigid_state thrown = at(0, 0, 0.4, 1);
  thrown.angular_velocity[0] = 4, thrown.angular_velocity[1] = 9;
  World world;
  world.colliders = {ground};
  world.setColliders();
  qv_instance* member = world.add(bar, h, thrown, true);
  qv_instance_config c = bar.config(h);
  c.rayleigh_alpha = 5;  // as World::add
  test::Instance alone(bar.model, c);
  ASSERT_EQ(qv_instance_set_rigid_state(alone.s, &thrown), QV_OK);
  const double g[3] = {0, 0, -kG};
  qv_instance_set_gravity(alone.s, g);
  ASSERT_EQ(qv_instance_set_colliders(alone.s, &ground, 1), QV_OK);
  int touching = 0;
  for (int i = 0; i < 240; ++i) {
    ASSERT_EQ(qv_world_step(world.w), 0);
    ASSERT_NE(qv_instance_step(alone.s), QV_STEP_RESET);
    touching += !world.contacts().empty();
  }
  const double apart = (bar.positions(member) - bar.positions(alone.s)).cwiseAbs().maxCoeff();
  std::printf("a bar thrown onto the ground, in a world of one and alone: %d steps with contacts, %.1e m apart at the end\n",
              touching, apart);
  EXPECT_GT(touching, 120);
  EXPECT_EQ(apart, 0.0);
}

// A still bar beside a kinematic ball that spins within its reach, not touching it: it would be
// woken at once, so it stays awake (it fell asleep and woke every half second, restarting its
// contacts' impulses each time); once the ball stops it sleeps.
TEST(World, AStillBarBesideAMovingColliderStaysAwake) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  World world(0.5, 0, 4096, kSleepSpeed);
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0),
                     makeCollider(QV_COLLIDER_SPHERE, {0.7, 0.05, 0.1, 0.05, 0, 0, 0, 0}, 0.5, 0)};
  world.colliders[1].angular_velocity[2] = 3;
  world.setColliders();
  qv_instance* s = world.add(bar, h, at(0.3, 0.05, 0.052), true);
  int asleepSteps = 0;
  for (int i = 0; i < 120; ++i) {
    ASSERT_EQ(qv_world_step(world.w), 0);
    asleepSteps += qv_instance_asleep(s);
  }
  world.colliders[1].angular_velocity[2] = 0;
  const bool sleepsOnceStopped = sleepsWithin(world, s, 60);
  std::printf("beside a spinning ball: asleep in %d of 120 steps; asleep once it stopped: %s\n", asleepSteps,
              sleepsOnceStopped ? "yes" : "no");
  EXPECT_EQ(asleepSteps, 0);
  EXPECT_TRUE(sleepsOnceStopped);
}

// In space, still but vibrating (its first mode bent, lightly damped): it must not fall asleep
// with the bend frozen in, only once the vibration has died down.
TEST(World, AVibratingBarDoesNotFallAsleep) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  World world(0.5, 0, 4096, kSleepSpeed);
  qv_instance* s = world.add(bar, h, at(0, 0, 0), false);
  std::vector<double> q(bar.info.r, 0.0);
  q[0] = 0.05;  // about 2 cm at the ends
  qv_instance_set_state(s, q.data(), nullptr, nullptr);
  double kinetic = 0, elastic = 0, start = 0;
  qv_instance_energies(s, &kinetic, &elastic);
  start = elastic;
  int fellAsleepAt = -1;
  for (int i = 0; i < 600 && fellAsleepAt < 0; ++i) {
    qv_world_step(world.w);
    if (qv_instance_asleep(s)) fellAsleepAt = i;
  }
  ASSERT_GE(fellAsleepAt, 0) << "still vibrating after 10 s";
  qv_instance_energies(s, &kinetic, &elastic);
  std::printf("a bar vibrating in space fell asleep after %.2f s, its elastic energy down to %.3g of the start\n",
              (fellAsleepAt + 1) * h, elastic / start);
  EXPECT_GT((fellAsleepAt + 1) * h, 1.0);
  EXPECT_LT(elastic, 1e-3 * start);
}

// A bar spawned through the middle of a cube resting on the ground, as a game places a prop inside
// a crate: its vertices deep inside took whichever face was nearest, their pushes opposed each
// other, and it flew off (here at 1136 m/s with only the push-out speed capped, measured). It must
// come out at a few m/s and come to rest beside the cube, and the cube stay where it was.
TEST(World, ABarSpawnedThroughACubeIsPushedOutWithoutFlyingOff) {
  FreeBar bar(16, {12, 2, 2}), cube(12, {4, 4, 4}, {0.6, 0.6, 0.6});
  const double h = 1.0 / 60;
  World world;
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  qv_instance* box = world.add(cube, h, at(0, 0, 0.3), true);
  qv_rigid_state through = at(0.08, 0.03, 0.31);  // off the centre: the geometry, not rounding, says which way out
  through.orientation[0] = std::cos(0.15), through.orientation[3] = std::sin(0.15);
  qv_instance* s = world.add(bar, h, through, true);
  double fastest = 0, spin = 0;
  for (int i = 0; i < 240; ++i) {
    ASSERT_EQ(qv_world_step(world.w), 0);
    for (qv_instance* b : {box, s}) {
      qv_rigid_state r;
      qv_instance_get_rigid_state(b, &r);
      fastest = std::max(fastest, Eigen::Vector3d(r.linear_velocity[0], r.linear_velocity[1], r.linear_velocity[2]).norm());
      spin = std::max(spin, Eigen::Vector3d(r.angular_velocity[0], r.angular_velocity[1], r.angular_velocity[2]).norm());
    }
  }
  qv_rigid_state end;
  qv_instance_get_rigid_state(s, &end);
  const Eigen::Vector3d out = centre(s);
  std::printf("a bar spawned through a cube: fastest %.2f m/s, %.0f rad/s; it ends at (%.3f, %.3f, %.3f), the cube at "
              "(%.3f, %.3f, %.3f)\n", fastest, spin, out.x(), out.y(), out.z(), centre(box).x(), centre(box).y(), centre(box).z());
  EXPECT_LT(fastest, 10.0);  // 4.95 m/s measured: each deep contact pushes at 1 m/s at most, the turning bar's pushes add
  EXPECT_LT(Eigen::Vector3d(end.linear_velocity[0], end.linear_velocity[1], end.linear_velocity[2]).norm(), 0.05);
  EXPECT_GT(std::max(std::fabs(out.x()), std::fabs(out.y())), 0.3);  // out of the cube's footprint
  EXPECT_NEAR(out.z(), 0.05, 0.01);                                    // on the ground beside it
  EXPECT_LT((centre(box) - Eigen::Vector3d(0, 0, 0.3)).norm(), 0.1);
}

// A soft bar lying on a slab that lies on the ground lies straight on it, as on the ground itself
// (contact_test.cpp, WithSoftContactsASoftBarLiesStraightOnTheGround): the slab holds its whole
// underside. Soft contacts on both (each gives way where the other pushes: a 3 m bar on a 3.2 m
// slab, both at 1 MPa), and on the bar only (a 1 m bar of 5 cm on a slab short enough to lie flat
// on contacts that hold its rigid shape).
TEST(World, WithSoftContactsASoftBarLiesStraightOnASlab) {
  const double h = 1.0 / 60;
  FreeBar longSlab(16, {16, 3, 1}, {3.2, 0.6, 0.1}), longBar(16, {30, 1, 1}, {3, 0.1, 0.1});
  FreeBar shortSlab(16, {6, 3, 1}, {1.2, 0.6, 0.1}), thinBar(16, {20, 1, 1}, {1, 0.05, 0.05});
  struct Case {
    const FreeBar &slab, &bar;
    bool softSlab, softBar;
  };
  for (const Case& c : {Case{longSlab, longBar, false, false}, Case{longSlab, longBar, true, true},
                        Case{shortSlab, thinBar, false, false}, Case{shortSlab, thinBar, false, true}}) {
    World world;
    world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
    world.setColliders();
    const double length = c.bar.info.bbox_max[0], height = c.bar.info.bbox_max[2];
    qv_instance* slab = world.add(c.slab, h, at(0.5 * c.slab.info.bbox_max[0], 0.3, 0.051), true, c.softSlab);
    qv_instance* bar = world.add(c.bar, h, at(0.5 * c.slab.info.bbox_max[0], 0.3, 0.1 + height / 2 + 0.006), true, c.softBar);
    double fastest = 0, slabFastest = 0;  // the fastest any vertex moved in a step of the last second
    Eigen::MatrixXd slabBefore, barBefore;
    for (int i = 0; i < 240; ++i) {
      ASSERT_EQ(qv_world_step(world.w), 0);
      const Eigen::MatrixXd slabNow = c.slab.positions(slab), barNow = c.bar.positions(bar);
      if (i > 180) {
        slabFastest = std::max(slabFastest, (slabNow - slabBefore).rowwise().norm().maxCoeff() / h);
        fastest = std::max(fastest, (barNow - barBefore).rowwise().norm().maxCoeff() / h);
      }
      slabBefore = slabNow, barBefore = barNow;
    }
    const Eigen::MatrixXd x = c.bar.positions(bar);
    const double* rest = qv_model_rest_positions(c.bar.model);
    double low = INFINITY, high = -INFINITY;
    for (int v = 0; v < c.bar.info.vertex_count; ++v)
      if (rest[3 * v + 2] < 1e-9) low = std::min(low, x(v, 2)), high = std::max(high, x(v, 2));
    std::printf("a %g m bar on a %g m slab, soft contacts on the slab %d, on the bar %d: the bar's underside between z = %.4g "
                "and %.4g m (the slab's top at 0.1 m); over the last second the bar moved at most %.2g m/s, the slab %.2g m/s\n", length,
                c.slab.info.bbox_max[0], c.softSlab, c.softBar, low, high, fastest, slabFastest);
    if (!c.softBar) {
      EXPECT_GT(high - low, 5e-3);  // it sags into the slab: 36 cm, and 8 mm
      continue;
    }
    EXPECT_LT(high - low, 2e-3);
    EXPECT_GT(low, 0.1 - 0.01);  // resting contacts sink about a slop on each side
    EXPECT_LT(fastest, 1e-5);
    // A slab on contacts that hold its rigid shape keeps its deformation fluttering under the bar
    // (0.9 mm/s at its vertices, as under a bar without soft contacts); on soft contacts it is still.
    if (c.softSlab) {
      EXPECT_LT(slabFastest, 1e-5);
    }
  }
}

// A world's instances' own parts of its steps and its solve's islands run in the caller's jobs
// (qv_world_set_jobs): twenty bars dropped into a bin (islands that merge as they land) and sixteen
// dropped apart on a grid (an island each), with sleeping on, stepped in three jobs run backwards
// on the calling thread and in two jobs on two threads, end bit for bit where one thread leaves
// them, contacts and sleep included.
TEST(World, StepsInJobsGiveTheSameBits) {
  FreeBar bar(16, {12, 2, 2});
  const double h = 1.0 / 60;
  struct Threads {
    static void run(void*, qv_job_function job, void* data, int count) {
      std::vector<std::thread> others;
      for (int i = 1; i < count; ++i) others.emplace_back(job, data, i);
      job(data, 0);
      for (std::thread& t : others) t.join();
    }
  };
  const qv_job_runner backwards{3, runBackwards, nullptr}, threads{2, Threads::run, nullptr};
  const auto dropApart = [&](World& world) {
    world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
    world.setColliders();
    for (int k = 0; k < 16; ++k) {
      qv_rigid_state s = at(0.8 * (k % 4), 0.8 * (k / 4), 0.1 + 0.05 * (k % 5));
      s.orientation[0] = std::cos(0.1 * k), s.orientation[1] = std::sin(0.1 * k);  // tilted: each lands its own way
      world.add(bar, h, s, true);
    }
  };
  for (const bool apart : {false, true}) {
    World one(0.5, 0, 4096, kSleepSpeed), three(0.5, 0, 4096, kSleepSpeed), two(0.5, 0, 4096, kSleepSpeed);
    ASSERT_EQ(qv_world_set_jobs(three.w, &backwards), QV_OK);
    ASSERT_EQ(qv_world_set_jobs(two.w, &threads), QV_OK);
    for (World* w : {&one, &three, &two}) {
      if (apart) {
        dropApart(*w);
      } else {
        dropTwentyIntoABin(*w, bar, h);
      }
    }
    const int n = static_cast<int>(one.bodies.size());
    const auto compare = [&](int steps) {
      for (World* w : {&one, &three, &two})
        for (int i = 0; i < steps; ++i) ASSERT_EQ(qv_world_step(w->w), 0);
      for (const World* w : {&three, &two}) {
        for (int k = 0; k < n; ++k) EXPECT_EQ(bar.positions(w->bodies[k]->s), bar.positions(one.bodies[k]->s)) << "bar " << k;
        EXPECT_EQ(asleep(*w), asleep(one));
        const std::vector<qv_contact> x = w->contacts(), y = one.contacts();
        ASSERT_EQ(x.size(), y.size());
        for (size_t k = 0; k < x.size(); ++k) EXPECT_EQ(std::memcmp(&x[k], &y[k], sizeof x[k]), 0) << "contact " << k;
      }
    };
    compare(30);  // landing
    const size_t landing = one.contacts().size();
    compare(270);
    std::printf("%d bars %s, in jobs as on one thread: %zu contacts after 0.5 s; %d asleep after 5 s\n", n,
                apart ? "dropped apart" : "in a bin", landing, asleep(one));
    EXPECT_GT(landing, 100u);
    EXPECT_GT(asleep(one), 0);
  }
  World world;
  const qv_job_runner none{0, runBackwards, nullptr}, runless{2, nullptr, nullptr};
  EXPECT_EQ(qv_world_set_jobs(world.w, &none), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_world_set_jobs(world.w, &runless), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_world_set_jobs(nullptr, &threads), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_world_set_jobs(world.w, &threads), QV_OK);
  EXPECT_EQ(qv_world_set_jobs(world.w, nullptr), QV_OK);  // back to the calling thread
}

// What a game does to a world, at random, 3000 times: steps (most often), adds and removes bars,
// wakes and moves them, sets jobs and clears them, saves and restores snapshots. The bookkeeping
// stays whole after each: every member is finite; the contacts name members only; a snapshot of
// the world restores (its checks refuse sleep groups and contacts that name no member); a removed
// bar is awake and steps alone.
TEST(World, RandomAddsRemovesWakesAndStepsKeepItsBookkeepingWhole) {
  FreeBar bar(10, {6, 1, 1});
  const double h = 1.0 / 60;
  qv_world_config c;
  qv_world_config_init(&c);
  c.max_instances = 8;
  c.sleep_time = 0.1;  // sleeping and waking often
  World world(c);
  world.colliders = {makeCollider(QV_COLLIDER_PLANE, {0, 0, 1, 0, 0, 0, 0, 0}, 0.5, 0)};
  world.setColliders();
  const qv_job_runner jobs{3, runBackwards, nullptr};
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> where(-0.3, 0.3), high(0.06, 0.3);
  const auto dropped = [&] { return at(where(rng), where(rng), high(rng)); };
  std::vector<qv_instance*> members, out;
  for (int k = 0; k < 8; ++k) {
    qv_instance* s = world.add(bar, h, dropped(), true);
    if (k < 5) {
      members.push_back(s);
    } else {
      ASSERT_EQ(qv_world_remove(world.w, s), QV_OK);
      out.push_back(s);
    }
  }
  std::uniform_int_distribution<int> action(0, 199);  // mostly steps, so that groups come to rest and sleep
  int steps = 0, removed = 0, added = 0, restored = 0, slept = 0;
  for (int i = 0; i < 3000; ++i) {
    const int a = action(rng);
    const auto pick = [&](std::vector<qv_instance*>& from) {
      return static_cast<size_t>(std::uniform_int_distribution<int>(0, static_cast<int>(from.size()) - 1)(rng));
    };
    if (a <= 2 && !members.empty()) {  // despawn
      const size_t k = pick(members);
      ASSERT_EQ(qv_world_remove(world.w, members[k]), QV_OK);
      EXPECT_EQ(qv_instance_asleep(members[k]), 0);
      ASSERT_NE(qv_instance_step(members[k]), QV_STEP_RESET);
      out.push_back(members[k]);
      members.erase(members.begin() + static_cast<long>(k));
      ++removed;
    } else if (a >= 3 && a <= 5 && !out.empty()) {  // spawn again, somewhere above
      const size_t k = pick(out);
      const qv_rigid_state s = dropped();
      ASSERT_EQ(qv_instance_set_rigid_state(out[k], &s), QV_OK);
      int index = -1;
      ASSERT_EQ(qv_world_add(world.w, out[k], &index), QV_OK);
      EXPECT_EQ(index, static_cast<int>(members.size()));
      members.push_back(out[k]);
      out.erase(out.begin() + static_cast<long>(k));
      ++added;
    } else if (a == 6 && !members.empty()) {
      qv_instance_wake(members[pick(members)]);
    } else if (a == 7 && !members.empty()) {  // the game moves one
      const qv_rigid_state s = dropped();
      ASSERT_EQ(qv_instance_set_rigid_state(members[pick(members)], &s), QV_OK);
    } else if (a == 8) {
      ASSERT_EQ(qv_world_set_jobs(world.w, i % 2 ? &jobs : nullptr), QV_OK);
    } else {
      ASSERT_EQ(qv_world_step(world.w), 0);
      ++steps;
    }
    for (qv_instance* s : members) ASSERT_TRUE(bar.positions(s).allFinite()) << "action " << i;
    for (const qv_contact& ct : world.contacts()) {
      ASSERT_LT(ct.instance, static_cast<int>(members.size())) << "action " << i;
      ASSERT_LT(ct.other, static_cast<int>(members.size())) << "action " << i;
    }
    std::vector<double> snapshot(qv_world_snapshot_size(world.w) / sizeof(double) + 1);
    const size_t used = qv_world_save_snapshot(world.w, snapshot.data());
    ASSERT_EQ(qv_world_restore_snapshot(world.w, snapshot.data(), used), QV_OK) << "action " << i;
    ++restored;
    int sleeping = 0;
    for (qv_instance* s : members) sleeping += qv_instance_asleep(s);
    slept = std::max(slept, sleeping);
  }
  std::printf("3000 random actions: %d steps, %d removals, %d additions, %d snapshots restored; up to %d asleep at once\n", steps,
              removed, added, restored, slept);
  EXPECT_GT(removed, 10);
  EXPECT_GT(added, 10);
  EXPECT_GT(slept, 1);
}

TEST(World, BadUseIsRefused) {
  FreeBar bar;
  World world;
  qv_instance_config grounded = bar.config(1.0 / 60);
  grounded.free_flight = 0;
  test::Instance pinned(bar.model, grounded), flying(bar.model, bar.config(1.0 / 60)), other(bar.model, bar.config(1.0 / 120));
  EXPECT_EQ(qv_world_add(world.w, pinned.s, nullptr), QV_ERROR_INVALID_ARGUMENT);
  int index = -1;
  EXPECT_EQ(qv_world_add(world.w, flying.s, &index), QV_OK);
  EXPECT_EQ(index, 0);
  EXPECT_EQ(qv_world_add(world.w, flying.s, nullptr), QV_ERROR_INVALID_ARGUMENT);  // already in
  EXPECT_EQ(qv_world_add(world.w, other.s, nullptr), QV_ERROR_INVALID_ARGUMENT);   // another time step
  const qv_collider bad = makeCollider(QV_COLLIDER_SPHERE, {0, 0, 0, -1, 0, 0, 0, 0});
  EXPECT_EQ(qv_world_set_colliders(world.w, &bad, 1), QV_ERROR_INVALID_ARGUMENT);
  qv_collider meshless = makeCollider(QV_COLLIDER_MESH, {0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(qv_world_set_colliders(world.w, &meshless, 1), QV_ERROR_INVALID_ARGUMENT);
  qv_world_config c;
  qv_world_config_init(&c);
  c.max_instances = 0;
  qv_world* none = nullptr;
  EXPECT_EQ(qv_world_create(&c, nullptr, &none), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(none, nullptr);
  for (const double speed : {-1.0, std::nan(""), HUGE_VAL}) {
    qv_world_config_init(&c);
    c.sleep_speed = speed;
    EXPECT_EQ(qv_world_create(&c, nullptr, &none), QV_ERROR_INVALID_ARGUMENT);
    qv_world_config_init(&c);
    c.sleep_time = speed;
    EXPECT_EQ(qv_world_create(&c, nullptr, &none), QV_ERROR_INVALID_ARGUMENT);
  }
  EXPECT_EQ(qv_world_remove(world.w, pinned.s), QV_ERROR_INVALID_ARGUMENT);  // not in it
  EXPECT_EQ(qv_world_remove(world.w, nullptr), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_world_remove(nullptr, flying.s), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_instance_asleep(flying.s), 0);
  qv_instance_wake(nullptr);  // ignored
  EXPECT_EQ(qv_instance_asleep(nullptr), 0);
}

// A bar spun at 300 rad/s (18 m/s turns a step, tip speeds of 92 m/s) beside another, its ends
// sweeping 4 cm below the other's underside: the straight paths the contacts' margins cover would
// reach 3 m, but the arcs never touch (kStraightTurn, contact.cpp). Until 2026-11-29 the contacts
// stopped ends that swing clear; now nothing touches, and the other bar stays where it is. Where
// the arcs do reach, they still touch.
TEST(World, ABodyTurningFastIsNotStoppedWhereItsEndsSwingClear) {
  FreeBar bar;
  ASSERT_NE(bar.model, nullptr);
  World world;
  qv_instance* spinning = world.add(bar, 1.0 / 60, {{0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0}, {0, 300, 0}}, false);
  qv_instance* still = world.add(bar, 1.0 / 60, {{0, 0, 0.4}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, false);
  for (int step = 0; step < 30; ++step) {
    qv_world_step(world.w);
    EXPECT_EQ(qv_world_contacts(world.w, nullptr, 0), 0) << "step " << step;
  }
  qv_rigid_state a, b;
  qv_instance_get_rigid_state(spinning, &a);
  qv_instance_get_rigid_state(still, &b);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(a.position[c], 0.0) << c;
    EXPECT_EQ(b.position[c], c == 2 ? 0.4 : 0.0) << c;
    EXPECT_EQ(b.linear_velocity[c], 0.0) << c;
  }
  // 7 cm nearer, the ends (0.304 m from the centre) sweep 2.4 cm into the other's underside: they
  // touch it and throw it up.
  World near;
  near.add(bar, 1.0 / 60, {{0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0}, {0, 300, 0}}, false);
  qv_instance* hit = near.add(bar, 1.0 / 60, {{0, 0, 0.33}, {1, 0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, false);
  int touched = 0;
  for (int step = 0; step < 5; ++step) {
    qv_world_step(near.w);
    touched += qv_world_contacts(near.w, nullptr, 0) > 0;
  }
  qv_instance_get_rigid_state(hit, &b);
  EXPECT_GT(touched, 0);
  EXPECT_GT(b.linear_velocity[2], 1.0);
}


} // namespace
} // namespace quiver
