// qv_triangle_mesh's signed distance against geometry it does not share code with: a cube mesh
// against the box's closed form (and, facing down, against its top face's), a fine sphere against
// |p| - R, a non-convex star's sign against the winding number (solid angles), its distance against
// the nearest of many surface samples;
// bad meshes refused with what and where.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "runtime/src/triangle_mesh.h"
#include "quiver/quiver.h"
#include "tests/support/box_surface.h"

namespace quiver {
namespace {

struct Surface {
  std::vector<double> positions;
  std::vector<int> triangles;
};

// The cube [-1, 1]^3 scaled by `half`, two triangles a face, outward.
Surface cube(const double half[3]) {
  test::BoxSurface box = test::boxSurface(half);
  return Surface{std::move(box.positions), std::move(box.triangles)};
}

// A UV sphere whose radius at direction d is radius(d): rings x segments, poles shared.
template <class Radius>
Surface sphere(int rings, int segments, Radius radius) {
  Surface s;
  const auto add = [&](double theta, double phi) {
    const Eigen::Vector3d d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    const Eigen::Vector3d p = radius(d) * d;
    s.positions.insert(s.positions.end(), {p[0], p[1], p[2]});
  };
  add(0, 0);
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) add(M_PI * i / rings, 2 * M_PI * j / segments);
  add(M_PI, 0);
  const int south = 1 + (rings - 1) * segments;
  const auto at = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) {
    s.triangles.insert(s.triangles.end(), {0, at(1, j), at(1, j + 1)});
    s.triangles.insert(s.triangles.end(), {south, at(rings - 1, j + 1), at(rings - 1, j)});
    for (int i = 1; i < rings - 1; ++i)
      s.triangles.insert(s.triangles.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  }
  return s;
}

struct Mesh {
  qv_triangle_mesh* mesh = nullptr;
  qv_result result;
  std::string message;
  explicit Mesh(const Surface& s) {
    char text[512] = "";
    result = qv_triangle_mesh_create(s.positions.data(), static_cast<int>(s.positions.size() / 3), s.triangles.data(),
                                     static_cast<int>(s.triangles.size() / 3), nullptr, &mesh, text, sizeof text);
    message = text;
  }
  ~Mesh() { qv_triangle_mesh_destroy(mesh); }
};

// Winding number of a closed surface about p (Van Oosterom & Strackee's solid angle): 1 inside, 0 outside.
double winding(const Surface& s, const Eigen::Vector3d& p) {
  double total = 0;
  for (size_t t = 0; t < s.triangles.size(); t += 3) {
    Eigen::Vector3d v[3];
    for (int k = 0; k < 3; ++k) v[k] = Eigen::Vector3d::Map(&s.positions[3 * s.triangles[t + k]]) - p;
    const double n[3] = {v[0].norm(), v[1].norm(), v[2].norm()};
    const double num = v[0].dot(v[1].cross(v[2]));
    const double den = n[0] * n[1] * n[2] + v[0].dot(v[1]) * n[2] + v[1].dot(v[2]) * n[0] + v[2].dot(v[0]) * n[1];
    total += 2 * std::atan2(num, den);
  }
  return total / (4 * M_PI);
}

TEST(TriangleMesh, ACubeMeasuresAsTheBoxDoes) {
  const double half[3] = {0.5, 1, 2};
  const Surface s = cube(half);
  Mesh m(s);
  ASSERT_EQ(m.result, QV_OK) << m.message;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 2000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    // The box's closed form: outside, the length of the excess; inside, minus the nearest face's distance.
    double outside = 0, inside = -INFINITY;
    for (int a = 0; a < 3; ++a) {
      const double q = std::fabs(p[a]) - half[a];
      outside += q > 0 ? q * q : 0;
      inside = std::max(inside, q);
    }
    const double expected = outside > 0 ? std::sqrt(outside) : inside;
    double d, n[3];
    ASSERT_TRUE(m.mesh->distance(p, INFINITY, d, n));
    ASSERT_NEAR(d, expected, 1e-12) << p[0] << " " << p[1] << " " << p[2];
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1, 1e-12);
  }
  // Beyond reach of the box: nothing computed.
  const double far[3] = {0, 0, 10};
  double d, n[3];
  EXPECT_FALSE(m.mesh->distance(far, 1.0, d, n));
  EXPECT_TRUE(m.mesh->distance(far, 8.5, d, n));
  EXPECT_DOUBLE_EQ(d, 8);
  EXPECT_EQ(n[2], 1);
}

// Facing down (a vertex on the underside of something above), only the top face counts: the
// distance to the nearest point of its rectangle, negative below its plane, and its normal.
TEST(TriangleMesh, FacingADirectionOnlyTheFacesAgainstItCount) {
  const double half[3] = {0.5, 1, 2}, down[3] = {0, 0, -1};
  Mesh m(cube(half));
  ASSERT_EQ(m.result, QV_OK) << m.message;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 2000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    const double cx = std::clamp(p[0], -half[0], half[0]), cy = std::clamp(p[1], -half[1], half[1]);
    const double length = std::sqrt((p[0] - cx) * (p[0] - cx) + (p[1] - cy) * (p[1] - cy) + (p[2] - half[2]) * (p[2] - half[2]));
    double d, n[3];
    ASSERT_TRUE(m.mesh->distance(p, INFINITY, d, n, nullptr, down));
    ASSERT_NEAR(d, p[2] < half[2] ? -length : length, 1e-12) << p[0] << " " << p[1] << " " << p[2];
    EXPECT_EQ(n[0], 0);
    EXPECT_EQ(n[1], 0);
    EXPECT_EQ(n[2], 1);
  }
}

TEST(TriangleMesh, AFineSphereMeasuresAsTheSphereDoes) {
  const double R = 0.7;
  const Surface s = sphere(64, 128, [&](const Eigen::Vector3d&) { return R; });
  Mesh m(s);
  ASSERT_EQ(m.result, QV_OK) << m.message;
  const double sagitta = R * (1 - std::cos(M_PI / 64));  // the chord's distance from the sphere
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    double d, n[3];
    ASSERT_TRUE(m.mesh->distance(p.data(), INFINITY, d, n));
    ASSERT_NEAR(d, p.norm() - R, 1.01 * sagitta);
    if (p.norm() > 0.1) {
      EXPECT_GT(Eigen::Vector3d::Map(n).dot(p.normalized()), 0.99);  // outward, radial
    }
  }
}

TEST(TriangleMesh, ANonConvexStarHasTheWindingNumbersSign) {
  // Bumps of 40% of the radius: concave valleys, saddles and vertices whose faces fold both ways.
  const auto radius = [](const Eigen::Vector3d& d) { return 1 + 0.4 * std::sin(5 * d[0]) * std::cos(4 * d[1]) * std::sin(3 * d[2] + 1); };
  const Surface s = sphere(24, 48, radius);
  Mesh m(s);
  ASSERT_EQ(m.result, QV_OK) << m.message;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  int inside = 0;
  for (int i = 0; i < 1500; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    double d, n[3];
    ASSERT_TRUE(m.mesh->distance(p.data(), INFINITY, d, n));
    const double w = winding(s, p);
    ASSERT_NEAR(w, std::round(w), 1e-6);
    ASSERT_EQ(d < 0, w > 0.5) << "at " << p.transpose() << ": distance " << d << ", winding number " << w;
    inside += d < 0;
    // No farther than the nearest vertex, and no nearer than the nearest of dense samples on the
    // triangles less their spacing.
    double nearestVertex = INFINITY, nearestSample = INFINITY;
    for (size_t v = 0; v < s.positions.size() / 3; ++v)
      nearestVertex = std::min(nearestVertex, (Eigen::Vector3d::Map(&s.positions[3 * v]) - p).norm());
    double spacing = 0;
    for (size_t t = 0; t < s.triangles.size(); t += 3) {
      const Eigen::Vector3d a = Eigen::Vector3d::Map(&s.positions[3 * s.triangles[t]]),
                            b = Eigen::Vector3d::Map(&s.positions[3 * s.triangles[t + 1]]),
                            c = Eigen::Vector3d::Map(&s.positions[3 * s.triangles[t + 2]]);
      constexpr int kSamples = 6;
      spacing = std::max(spacing, std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) / kSamples);
      for (int x = 0; x <= kSamples; ++x)
        for (int y = 0; x + y <= kSamples; ++y)
          nearestSample = std::min(nearestSample, (a + (b - a) * x / kSamples + (c - a) * y / kSamples - p).norm());
    }
    ASSERT_LE(std::fabs(d), nearestVertex + 1e-12);
    ASSERT_GE(std::fabs(d), nearestSample - spacing);
  }
  EXPECT_GT(inside, 100);  // both sides seen
  EXPECT_LT(inside, 1400);
}

// A hint (a triangle measured first, so that the search skips what lies farther) changes nothing
// but the work: on the bumpy star, any hint, near or far, and facing or not, gives the distance
// and sign the search alone gives, bit for bit, and a hint out of range is ignored.
TEST(TriangleMesh, AHintChangesNothingButTheWork) {
  const auto radius = [](const Eigen::Vector3d& d) { return 1 + 0.4 * std::sin(5 * d[0]) * std::cos(4 * d[1]) * std::sin(3 * d[2] + 1); };
  const Surface s = sphere(24, 48, radius);
  Mesh m(s);
  ASSERT_EQ(m.result, QV_OK) << m.message;
  const int triangles = static_cast<int>(s.triangles.size() / 3);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.5, 1.5), nudge(-0.02, 0.02);
  std::uniform_int_distribution<int> any(0, triangles - 1);
  const double up[3] = {0, 0, 1};
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng)), near = p + Eigen::Vector3d(nudge(rng), nudge(rng), nudge(rng));
    const double* facing = i % 3 == 0 ? up : nullptr;
    double d, n[3];
    int t = -1;
    if (!m.mesh->distance(p.data(), INFINITY, d, n, &t, facing)) continue;
    int nearT = -1;
    double unused, un[3];
    m.mesh->distance(near.data(), INFINITY, unused, un, &nearT, facing);  // what a query nearby finds
    for (const int hint : {t, nearT, any(rng), -1, triangles}) {
      double dh, nh[3];
      ASSERT_TRUE(m.mesh->distance(p.data(), INFINITY, dh, nh, nullptr, facing, hint));
      ASSERT_EQ(dh, d) << "at " << p.transpose() << " with hint " << hint;
    }
  }
}

TEST(TriangleMesh, ANeedlesTipIsOnTheRightSide) {
  // Around a sharp tip the closest point is the tip for points on every side, and one face's normal
  // alone gives the wrong sign for half of them: the angle-weighted vertex normal decides.
  const Surface s{{0.1, 0, 0, 0, 0.1, 0, -0.1, 0, 0, 0, -0.1, 0, 0, 0, 2, 0, 0, -2},
                  {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4, 1, 0, 5, 2, 1, 5, 3, 2, 5, 0, 3, 5}};
  Mesh m(s);
  ASSERT_EQ(m.result, QV_OK) << m.message;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), (i % 2 ? 2 : -2) + u(rng));
    double d, n[3];
    ASSERT_TRUE(m.mesh->distance(p.data(), INFINITY, d, n));
    ASSERT_EQ(d < 0, winding(s, p) > 0.5) << "at " << p.transpose() << ": distance " << d;
  }
}

TEST(TriangleMesh, AnInwardMeshIsTurnedOutward) {
  const double half[3] = {1, 1, 1};
  Surface s = cube(half);
  for (size_t t = 0; t < s.triangles.size(); t += 3) std::swap(s.triangles[t + 1], s.triangles[t + 2]);
  Mesh m(s);
  ASSERT_EQ(m.result, QV_OK) << m.message;
  const double centre[3] = {0, 0, 0.5};
  double d, n[3];
  ASSERT_TRUE(m.mesh->distance(centre, INFINITY, d, n));
  EXPECT_DOUBLE_EQ(d, -0.5);
  EXPECT_EQ(n[2], 1);
}

TEST(TriangleMesh, BadMeshesAreRefusedSayingWhatAndWhere) {
  const double half[3] = {1, 1, 1};
  const auto expectRefused = [](const Surface& s, const std::string& what) {
    Mesh m(s);
    EXPECT_EQ(m.result, QV_ERROR_FORMAT) << what;
    EXPECT_EQ(m.mesh, nullptr);
    EXPECT_NE(m.message.find(what), std::string::npos) << m.message;
  };
  Surface open = cube(half);
  open.triangles.resize(open.triangles.size() - 3);
  expectRefused(open, "3 edges with one triangle (open)");
  Surface fin = cube(half);  // a fin on an edge: three triangles share it
  fin.positions.insert(fin.positions.end(), {3, 3, 3});
  fin.triangles.insert(fin.triangles.end(), {0, 4, 8, 4, 0, 8});
  expectRefused(fin, "shared by more than two (non-manifold)");
  Surface flipped = cube(half);
  std::swap(flipped.triangles[1], flipped.triangles[2]);
  expectRefused(flipped, "run the same way by both triangles");
  Surface flat = cube(half);
  flat.triangles[2] = flat.triangles[1];
  expectRefused(flat, "triangle 0");
  Surface nan = cube(half);
  nan.positions[7] = NAN;
  expectRefused(nan, "vertex 2: coordinate is not finite");
  Surface outOfRange = cube(half);
  outOfRange.triangles[5] = 8;
  expectRefused(outOfRange, "triangle 1: vertex index 8 is not in 0..7");
  expectRefused(Surface{{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}}, "at least 4 vertices");
}

} // namespace
} // namespace quiver
