#include <gtest/gtest.h>

#include <cmath>

#include "common/box_mesh.h"
#include "common/mesh_quality.h"

using namespace quiver;

TEST(MeshQuality, RegularTetHasUnitNormalisedVolumeAndArccosThirdDihedrals) {
  TetMesh m;
  m.vertices = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  m.tets = {{0, 1, 2, 3}};
  if (signedVolume6(m, 0) < 0) std::swap(m.tets[0][1], m.tets[0][2]);
  MeshQuality q = measureQuality(m);
  EXPECT_NEAR(q.normalisedVolume.min, 1.0, 1e-12);
  const double expected = std::acos(1.0 / 3.0) * 180 / std::acos(-1.0);  // 70.5288 degrees
  EXPECT_NEAR(q.dihedralDegrees.min, expected, 1e-9);
  EXPECT_NEAR(q.dihedralDegrees.max, expected, 1e-9);
  EXPECT_NEAR(q.edgeLength.min, std::sqrt(8.0), 1e-12);
  EXPECT_NEAR(q.tetVolume.max, 8.0 / 3.0, 1e-12);  // the cube [-1,1]^3 minus four corners of 4/3
}

TEST(MeshQuality, KuhnCubeDihedralsAreRightAnglesAndSixtyDegrees) {
  // Each Kuhn tet of a unit cube has dihedral angles of 90, 60 and 45 degrees only.
  MeshQuality q = measureQuality(makeBoxMesh({1, 1, 1}, {1, 1, 1}));
  EXPECT_NEAR(q.dihedralDegrees.min, 45, 1e-9);
  EXPECT_NEAR(q.dihedralDegrees.max, 90, 1e-9);
  EXPECT_NEAR(q.tetVolume.min, 1.0 / 6.0, 1e-12);
  EXPECT_NEAR(q.edgeLength.max, std::sqrt(3.0), 1e-12);
}
