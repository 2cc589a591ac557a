// An artist's surface before tetrahedralization (common/surface_check.h): a closed cube passes with
// its volume; what can be repaired is, and said; every other problem is an error with its count
// and first place.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/mesh_error.h"
#include "common/surface_check.h"

namespace quiver {
namespace {

struct Soup {
  std::vector<double> x;
  std::vector<int> t;
};

// An axis-aligned cube [lo, lo + size]^3 appended to `s`, outward, two triangles a face.
void addCube(Soup& s, double lo, double size) {
  const int base = static_cast<int>(s.x.size() / 3);
  for (int k = 0; k < 8; ++k)
    for (int a = 0; a < 3; ++a) s.x.push_back(lo + ((k >> a) & 1 ? size : 0));
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads)
    for (int k : {q[0], q[1], q[2], q[0], q[2], q[3]}) s.t.push_back(base + k);
}

std::string errorOf(const Soup& s) {
  try {
    checkSurface(s.x, s.t, "art.obj");
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

TEST(SurfaceCheck, AClosedCubePassesWithItsVolume) {
  Soup s;
  addCube(s, 0, 2);
  const CheckedSurface c = checkSurface(s.x, s.t, "cube");
  EXPECT_EQ(c.triangles.size(), 12u);
  EXPECT_NEAR(c.volume, 8, 1e-12);
  EXPECT_TRUE(c.repairs.empty());
}

TEST(SurfaceCheck, RepairsWhatItCanAndSaysSo) {
  Soup s;
  addCube(s, 0, 2);
  std::swap(s.t[4], s.t[5]);                         // the second triangle turned against its neighbours
  s.t.insert(s.t.end(), {0, 0, 1});                  // a degenerate one
  s.t.insert(s.t.end(), {s.t[0], s.t[1], s.t[2]});   // the first, again
  addCube(s, 0.5, 0.5);                              // a piece inside
  const CheckedSurface c = checkSurface(s.x, s.t, "cube");
  for (const std::string& r : c.repairs) std::printf("repair: %s\n", r.c_str());
  ASSERT_EQ(c.repairs.size(), 4u);
  EXPECT_EQ(c.repairs[0], "dropped 1 degenerate triangles (a repeated corner or no area)");
  EXPECT_EQ(c.repairs[1], "dropped 1 repeated triangles");
  EXPECT_EQ(c.repairs[2], "turned 1 triangles to agree with their neighbours");
  EXPECT_EQ(c.repairs[3], "set aside 1 pieces inside the largest (they are carried, not simulated)");
  EXPECT_EQ(c.triangles.size(), 12u);
  EXPECT_NEAR(c.volume, 8, 1e-12);
  Soup inward;
  addCube(inward, 0, 1);
  for (size_t k = 0; k < inward.t.size(); k += 3) std::swap(inward.t[k + 1], inward.t[k + 2]);
  const CheckedSurface turned = checkSurface(inward.x, inward.t, "inward");
  EXPECT_EQ(turned.repairs.at(0), "turned 1 inward-facing pieces outward");
  EXPECT_NEAR(turned.volume, 1, 1e-12);
}

TEST(SurfaceCheck, EveryOtherProblemIsNamedWithItsCount) {
  Soup open;
  addCube(open, 0, 1);
  open.t.resize(open.t.size() - 3);
  EXPECT_EQ(errorOf(open).rfind("art.obj: not closed: 3 open edges (holes), the first between vertex ", 0), 0u) << errorOf(open);
  Soup fin;  // two cubes sharing an edge: four triangles on it
  addCube(fin, 0, 1);
  const int base = 8;
  addCube(fin, 0, 1);
  for (int k = 0; k < 8; ++k) fin.x[3 * (base + k)] += 1, fin.x[3 * (base + k) + 1] += 1;  // [1,2] x [1,2] x [0,1]
  for (int& v : fin.t)  // its corners on the line x = y = 1 are the first cube's
    if (v == base + 0) v = 3; else if (v == base + 4) v = 7;
  EXPECT_NE(errorOf(fin).find("edges shared by more than two triangles (non-manifold)"), std::string::npos) << errorOf(fin);
  Soup two;
  addCube(two, 0, 1);
  addCube(two, 3, 1);
  EXPECT_NE(errorOf(two).find("2 separate pieces: 1 outside the largest hold 5% of its volume or more, the first at vertex 8 (3, 3, 3)"),
            std::string::npos)
      << errorOf(two);
  Soup folded;  // a corner pushed through the opposite face
  addCube(folded, 0, 1);
  folded.x[3 * 7 + 0] = 0.6, folded.x[3 * 7 + 1] = 0.3, folded.x[3 * 7 + 2] = -0.5;
  EXPECT_NE(errorOf(folded).find("pairs of triangles cross each other (self-intersections)"), std::string::npos) << errorOf(folded);
  Soup nan;
  addCube(nan, 0, 1);
  nan.x[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(errorOf(nan), "art.obj: vertex 1 (1, nan, 0): a coordinate is not finite");
  Soup huge;
  addCube(huge, 0, 1e12);
  EXPECT_NE(errorOf(huge).find("a coordinate beyond 1e9"), std::string::npos);
  // A surface under a micrometre across once went on to fail in the eigensolver or the export.
  Soup tiny;
  addCube(tiny, 0, 1e-30);
  EXPECT_EQ(errorOf(tiny), "art.obj: the surface spans 1e-30 m at most, under a micrometre (not in metres?): scale the "
                           "surface first");
  Soup small;  // a millimetre: no complaint of size
  addCube(small, 0, 1e-3);
  EXPECT_EQ(errorOf(small).find("micrometre"), std::string::npos);
  EXPECT_EQ(errorOf(Soup{}), "art.obj: no closed surface: 0 usable triangles");
}

} // namespace
} // namespace quiver
