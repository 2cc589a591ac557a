// The broad phase against testing every pair: each pair of balls that touch (centres closer than
// the sum of their radii, the half widths) is among its overlaps, each overlap comes once, along
// whichever axis the balls spread, and the lists per body hold the same pairs in ascending order;
// when they do not fit it says so. A contact solve of a crowd of flying bars finds and solves the
// same contacts, bit for bit, with the broad phase as testing every pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "free_bar.h"
#include "runtime/src/broad_phase.h"
#include "runtime/src/contact.h"
#include "runtime_fixture.h"

namespace quiver::rt {
namespace {

struct Scene {
  std::vector<char> block;
  BroadPhase broad;
  explicit Scene(int bodies) {
    BlockCarver measure(nullptr);
    broad.carve(measure, bodies);
    block.resize(measure.size() + 64);
    char* base = block.data() + (64 - reinterpret_cast<uintptr_t>(block.data()) % 64) % 64;
    BlockCarver place(base);
    broad.carve(place, bodies);
  }
};

std::set<std::pair<int, int>> overlaps(const BroadPhase& b) {
  std::set<std::pair<int, int>> out;
  forEachOverlap(b, [&](int i, int j) {
    EXPECT_NE(i, j);
    EXPECT_TRUE(out.insert({std::min(i, j), std::max(i, j)}).second) << "pair " << i << ", " << j << " twice";
  });
  return out;
}

TEST(BroadPhase, EveryPairOfTouchingBallsIsAnOverlapOnceAndTheListsAgree) {
  std::mt19937 rng(3);
  // Crowded to sparse, spread least along y; then along z alone.
  const struct {
    double extent, stretch[3];
  } layouts[] = {{1, {1, 0.3, 1}}, {10, {1, 0.3, 1}}, {100, {1, 0.3, 1}}, {10, {0.01, 0.01, 1}}};
  for (const auto& layout : layouts) {
    const double extent = layout.extent;
    const int n = 400;
    Scene scene(n);
    BroadPhase& b = scene.broad;
    std::uniform_real_distribution<double> where(-extent, extent), size(0.05, 1.0);
    for (int i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) b.centres[3 * i + a] = where(rng) * layout.stretch[a];
      b.halfWidth[i] = size(rng);
    }
    sortIntervals(b, n);
    const std::set<std::pair<int, int>> found = overlaps(b);
    int touching = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        const double d = std::hypot(b.centres[3 * i] - b.centres[3 * j], b.centres[3 * i + 1] - b.centres[3 * j + 1],
                                    b.centres[3 * i + 2] - b.centres[3 * j + 2]);
        if (d > b.halfWidth[i] + b.halfWidth[j]) continue;
        ++touching;
        EXPECT_TRUE(found.count({i, j})) << "touching balls " << i << " and " << j << " missed";
      }
    listOverlaps(b);
    std::printf("%d balls in a box of half size %g (x %g, y %g, z %g): %d pairs touch, %zu overlaps of %d pairs; lists %s\n",
                n, extent, layout.stretch[0], layout.stretch[1], layout.stretch[2], touching, found.size(), n * (n - 1) / 2,
                b.rowsValid ? "fit" : "do not fit");
    if (extent > 1) {
      EXPECT_LT(found.size(), static_cast<size_t>(n * (n - 1) / 8));  // far fewer than all pairs
    }
    ASSERT_EQ(b.rowsValid, 2 * found.size() <= static_cast<size_t>(b.neighbourCapacity));
    if (!b.rowsValid) continue;
    size_t listed = 0;
    for (int i = 0; i < n; ++i) {
      const int* row = b.neighbours + b.rowStart[i];
      const int length = b.rowStart[i + 1] - b.rowStart[i];
      EXPECT_TRUE(std::is_sorted(row, row + length)) << "row " << i;
      for (int k = 0; k < length; ++k) EXPECT_TRUE(found.count({std::min(i, row[k]), std::max(i, row[k])}));
      listed += static_cast<size_t>(length);
    }
    EXPECT_EQ(listed, 2 * found.size());
  }
}

// Two scenes: forty bars along 8 m through each other, most slow and one in five fast and
// spinning (a slow pair's margin then grows with its group's speed), and four exact layers of four
// bars laid crosswise, each touching the one below (many contacts equally deep, so which a full
// list keeps depends on the order it meets them). The same contacts in the same order with the
// same impulses, and the same frames' momenta after the solve, with the broad phase and testing
// every pair; with room for all contacts and with a full list.
std::vector<qv_rigid_state> crowd() {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> where(-1, 1), turn(-1, 1);
  std::vector<qv_rigid_state> out(40);
  for (size_t k = 0; k < out.size(); ++k) {
    qv_rigid_state& s = out[k];
    const double fast = k % 5 == 0 ? 1 : 0.02;
    double q[4], norm = 0;
    for (double& c : q) c = turn(rng), norm += c * c;
    for (int a = 0; a < 4; ++a) s.orientation[a] = q[a] / std::sqrt(norm);
    for (int a = 0; a < 3; ++a) {
      s.position[a] = where(rng) * (a == 0 ? 4 : a == 1 ? 1 : 0.5);
      s.linear_velocity[a] = 5 * fast * where(rng);
      s.angular_velocity[a] = 5 * fast * where(rng);
    }
  }
  return out;
}

std::vector<qv_rigid_state> layers() {
  std::vector<qv_rigid_state> out;
  for (int layer = 0; layer < 4; ++layer)
    for (int k = 0; k < 4; ++k) {
      const double across = -0.24 + 0.16 * k, yaw = layer % 2 ? M_PI / 2 : 0;
      qv_rigid_state s = {{layer % 2 ? across : 0, layer % 2 ? 0 : across, 0.05 + 0.1 * layer},
                          {std::cos(yaw / 2), 0, 0, std::sin(yaw / 2)}, {0, 0, 0}, {0, 0, 0}};
      out.push_back(s);
    }
  return out;
}

TEST(BroadPhase, AContactSolveFindsWhatTestingEveryPairFinds) {
  test::FreeBar bar(16, {6, 1, 1});
  const double h = 1.0 / 60;
  for (const auto& scene : {crowd(), layers()})
    for (const int capacity : {100000, 60}) {
      const int n = static_cast<int>(scene.size());
      std::vector<std::unique_ptr<test::Instance>> instances[2];
      std::vector<ContactBody> bodies[2];
      std::vector<Contact> contacts[2], previous[2];
      std::vector<ContactTurns> turns[2];
      std::vector<int> order[2];
      std::vector<ContactPair> pairs[2];
      ContactList lists[2];
      for (int set = 0; set < 2; ++set) {
        bodies[set].resize(n);
        for (int i = 0; i < n; ++i) {
          instances[set].push_back(std::make_unique<test::Instance>(bar.model, bar.config(h)));
          qv_instance* s = instances[set].back()->s;
          ASSERT_EQ(qv_instance_set_rigid_state(s, &scene[i]), QV_OK);
          const double g[3] = {0, 0, -9.81};
          qv_instance_set_gravity(s, g);
          s->beginStep();
          bodies[set][i].instance = s;
        }
        contacts[set].resize(capacity), previous[set].resize(capacity), pairs[set].resize(capacity);
        turns[set].resize(capacity), order[set].resize(capacity);
        lists[set].contacts = contacts[set].data(), lists[set].previous = previous[set].data();
        lists[set].turns = turns[set].data(), lists[set].order = order[set].data();
        lists[set].pairs = pairs[set].data(), lists[set].capacity = capacity;
      }
      Scene broad(n);
      takeMomenta(bodies[0].data(), n, nullptr, 0, h, &broad.broad);
      solveContacts(bodies[0].data(), n, nullptr, 0, ContactMaterial{}, lists[0], h, &broad.broad);
      takeMomenta(bodies[1].data(), n, nullptr, 0, h, nullptr);
      solveContacts(bodies[1].data(), n, nullptr, 0, ContactMaterial{}, lists[1], h, nullptr);
      int candidates = 0;
      forEachOverlap(broad.broad, [&](int, int) { ++candidates; });
      std::printf("%d bars, room for %d contacts: %d contacts (%d touching) from %d candidate pairs of %d\n", n, capacity,
                  lists[0].count, lists[0].touching, candidates, n * (n - 1) / 2);
      EXPECT_TRUE(broad.broad.rowsValid);
      ASSERT_GT(lists[1].count, 0);
      EXPECT_EQ(lists[0].full, capacity == 60);
      ASSERT_EQ(lists[0].count, lists[1].count);
      for (int k = 0; k < lists[0].count; ++k) {
        const Contact &a = lists[0].contacts[k], &b = lists[1].contacts[k];
        ASSERT_EQ(std::make_pair(a.body, a.other), std::make_pair(b.body, b.other)) << "contact " << k;
        ASSERT_EQ(a.vertex, b.vertex) << "contact " << k;
        EXPECT_EQ(std::memcmp(&a.normalImpulse, &b.normalImpulse, sizeof(double)), 0) << "contact " << k;
        EXPECT_EQ(std::memcmp(a.tangentImpulse, b.tangentImpulse, sizeof a.tangentImpulse), 0) << "contact " << k;
      }
      for (int i = 0; i < n; ++i) {
        const RigidFrame &a = instances[0][i]->s->frame, &b = instances[1][i]->s->frame;
        EXPECT_EQ(std::memcmp(a.velocity, b.velocity, sizeof a.velocity), 0) << "body " << i;
        EXPECT_EQ(std::memcmp(a.angularMomentum, b.angularMomentum, sizeof a.angularMomentum), 0) << "body " << i;
      }
    }
}

TEST(BroadPhase, ListsThatDoNotFitAreRefused) {
  const int n = 2 * BroadPhase::kNeighboursPerBody + 2;  // all at one point: n - 1 overlaps each
  Scene scene(n);
  BroadPhase& b = scene.broad;
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) b.centres[3 * i + a] = 0;
    b.halfWidth[i] = 1;
  }
  sortIntervals(b, n);
  EXPECT_EQ(overlaps(b).size(), static_cast<size_t>(n * (n - 1) / 2));
  listOverlaps(b);
  EXPECT_FALSE(b.rowsValid);
}

} // namespace
} // namespace quiver::rt
