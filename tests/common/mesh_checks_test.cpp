// Validation after reading: each problem is named by file, line and element.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/box_mesh.h"
#include "common/fixed_vertices.h"
#include "common/mesh_checks.h"
#include "common/mesh_error.h"
#include "tests/support/test_support.h"

using namespace quiver;

namespace {

// A raw mesh as a reader would return it, with each tet "written" on line 100 + t.
RawMesh rawFrom(TetMesh mesh) {
  RawMesh r;
  r.source.file = "m.msh";
  for (int t = 0; t < mesh.tetCount(); ++t) r.source.addTet(100 + t, t + 1);
  for (int v = 0; v < mesh.vertexCount(); ++v) r.source.vertexFileId.push_back(v + 1);
  r.mesh = std::move(mesh);
  return r;
}

std::string errorOf(RawMesh raw, MeshCheckOptions options = {}) {
  try {
    checkMesh(std::move(raw), options);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(MeshChecks, ValidBoxPassesUnchanged) {
  TetMesh box = makeBoxMesh({1, 2, 3}, {2, 2, 2});
  CheckedMesh c = checkMesh(rawFrom(box));
  EXPECT_EQ(c.mesh.tets, box.tets);
  EXPECT_EQ(c.mesh.vertices, box.vertices);
  EXPECT_TRUE(c.warnings.empty());
}

TEST(MeshChecks, InvertedTetRefusedOrFlipped) {
  TetMesh box = makeBoxMesh({1, 1, 1}, {1, 1, 1});
  std::swap(box.tets[3][0], box.tets[3][1]);
  std::string msg = errorOf(rawFrom(box));
  EXPECT_NE(msg.find("m.msh:103: element 4 is inverted: signed volume -0.166667"), std::string::npos) << msg;
  MeshCheckOptions fix;
  fix.fixOrientation = true;
  CheckedMesh c = checkMesh(rawFrom(box), fix);
  EXPECT_EQ(c.flippedTets, 1);
  for (int t = 0; t < c.mesh.tetCount(); ++t) EXPECT_NEAR(signedVolume6(c.mesh, t), 1.0, 1e-12);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("element 4"), std::string::npos);
}

TEST(MeshChecks, DegenerateTetsAreNamed) {
  TetMesh flat = makeBoxMesh({1, 1, 1}, {1, 1, 1});
  flat.vertices.push_back({0.5, 0.5, 0});
  flat.vertices.push_back({0.25, 0.5, 0});
  flat.tets.push_back({0, 1, 8, 9});  // four vertices on the plane z = 0
  std::string msg = errorOf(rawFrom(flat));
  EXPECT_NE(msg.find("m.msh:106: element 7 is degenerate: volume 0"), std::string::npos) << msg;

  TetMesh repeated = makeBoxMesh({1, 1, 1}, {1, 1, 1});
  repeated.tets[0][1] = repeated.tets[0][0];
  EXPECT_NE(errorOf(rawFrom(repeated)).find("element 1 is degenerate"), std::string::npos);

  // Scale independence: a tiny but well-shaped mesh is fine.
  TetMesh tiny = makeBoxMesh({1e-9, 1e-9, 1e-9}, {1, 1, 1});
  EXPECT_EQ(errorOf(rawFrom(tiny)), "");
}

TEST(MeshChecks, DuplicateTetsNameBoth) {
  TetMesh box = makeBoxMesh({1, 1, 1}, {1, 1, 1});
  Tet again = box.tets[2];
  std::swap(again[0], again[3]);
  std::swap(again[1], again[2]);  // same vertices, same orientation, other order
  box.tets.push_back(again);
  std::string msg = errorOf(rawFrom(box));
  EXPECT_NE(msg.find("element 7 has the same four vertices as m.msh:102: element 3"), std::string::npos) << msg;
}

TEST(MeshChecks, NonFiniteAndOutOfRangeAreRefused) {
  TetMesh box = makeBoxMesh({1, 1, 1}, {1, 1, 1});
  TetMesh nan = box;
  nan.vertices[5].y() = std::nan("");
  EXPECT_NE(errorOf(rawFrom(nan)).find("m.msh: vertex 6 has a non-finite coordinate"), std::string::npos);
  TetMesh range = box;
  range.tets[1][2] = 8;
  EXPECT_NE(errorOf(rawFrom(range)).find("m.msh:101: element 2 refers to vertex index 8"), std::string::npos);
  TetMesh empty;
  EXPECT_NE(errorOf(rawFrom(empty)).find("no tetrahedra"), std::string::npos);
}

TEST(MeshChecks, UnreferencedVerticesAreDroppedAndRemapped) {
  TetMesh box = makeBoxMesh({1, 1, 1}, {1, 1, 1});
  box.vertices.insert(box.vertices.begin(), Eigen::Vector3d(9, 9, 9));  // unused vertex 0
  for (Tet& t : box.tets)
    for (int& v : t) ++v;
  CheckedMesh c = checkMesh(rawFrom(box));
  EXPECT_EQ(c.mesh.vertexCount(), 8);
  EXPECT_EQ(c.loadedVertex[0], -1);
  EXPECT_EQ(c.loadedVertex[1], 0);
  EXPECT_EQ(c.fileVertex[0], 1);
  EXPECT_EQ(c.mesh.vertices[0], Eigen::Vector3d(0, 0, 0));
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("dropped 1 vertices"), std::string::npos);
  EXPECT_NEAR(totalVolume(c.mesh), 1.0, 1e-12);

  // Fixed-vertex indices refer to the file's numbering and follow the remap.
  FixedVertexRequest byIndex;
  byIndex.lists = {{"--fix-indices", {1, 2}, 0}};
  EXPECT_EQ(selectFixedVertices(c, byIndex), (std::vector<int>{0, 1}));
  byIndex.lists = {{"--fix-indices", {0}, 0}};
  EXPECT_EQ(test::errorOf<MeshError>([&] { selectFixedVertices(c, byIndex); }),
            "--fix-indices: vertex 0 belongs to no tet and was dropped");
  byIndex.lists = {{"f.bou", {9}, 1}};  // the file's vertex 10, one past the last
  EXPECT_EQ(test::errorOf<MeshError>([&] { selectFixedVertices(c, byIndex); }),
            "f.bou: vertex 10 is out of range [1, 9] (numbered from 1)");
}

TEST(FixedVertices, UnionOfSourcesAndEmptySelectionIsAnError) {
  CheckedMesh c = checkMesh(rawFrom(makeBoxMesh({2, 1, 1}, {2, 1, 1})));
  FixedVertexRequest r;
  r.selectors = {"x<0.5"};
  r.lists = {{"f.bou", {2}, 1}};  // vertex 3 (1-based) = (2,0,0)
  std::vector<int> fixed = selectFixedVertices(c, r);
  EXPECT_EQ(fixed, (std::vector<int>{0, 2, 3, 6, 9}));
  r.selectors = {"x<-1"};
  try {
    selectFixedVertices(c, r);
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("'x<-1' selects no vertex; the mesh spans x [0, 2]"), std::string::npos)
        << e.what();
  }
  r.selectors.clear();
  r.lists = {{"empty.bou", {}, 1}};
  EXPECT_EQ(test::errorOf<MeshError>([&] { selectFixedVertices(c, r); }), "empty.bou: lists no vertex");
}
