// TetGen .node/.ele reader and writer: hand-written samples in both bases, round trips, bad input.
#include <limits>

#include <gtest/gtest.h>

#include "formats/mesh/read_mesh.h"
#include "formats/mesh/write_mesh.h"
#include "tests/formats/mesh/text_mesh_test_support.h"

namespace quiver {
namespace {

using test::expectErrorAt;
using test::lineOf;
using test::meshErrorOf;
using test::replaced;

// Two tets sharing a face; vertices carry one attribute and a boundary marker, tets a region
// (written as a real, as TetGen does) and a second attribute.
const std::string kNode1 = R"(# 5 vertices, 1 attribute, boundary markers
5 3 1 1
1 0 0 0 0.5 1
2 1.5 0 0 0.5 1
# a comment between records
3 0 -2.25 0 0.5 0
4 0 0 1e-3 -1 1   # a comment after a record
5 1 1 1 2 0
)";
const std::string kEle1 = R"(2 4 2
# number, 4 vertices, region, another attribute
1 1 2 3 4 2.0 0.25
2 2 3 4 5 -3 7
)";

// The same mesh numbered from 0.
const std::string kNode0 = R"(5 3 1 1
0 0 0 0 0.5 1
1 1.5 0 0 0.5 1
2 0 -2.25 0 0.5 0
3 0 0 1e-3 -1 1
4 1 1 1 2 0
)";
const std::string kEle0 = R"(2 4 2
0 0 1 2 3 2.0 0.25
1 1 2 3 4 -3 7
)";

RawMesh parse(const std::string& node, const std::string& ele) { return parseTetGen(node, ele, "s.node", "s.ele"); }

std::string errorOf(const std::string& node, const std::string& ele) {
  return meshErrorOf([&] { parse(node, ele); });
}

TEST(TetGenRead, OneBasedSampleWithAttributesMarkersAndComments) {
  const RawMesh raw = parse(kNode1, kEle1);
  const TetMesh& mesh = raw.mesh;
  ASSERT_EQ(mesh.vertexCount(), 5);
  EXPECT_EQ(mesh.vertices[1], Eigen::Vector3d(1.5, 0, 0));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3d(0, -2.25, 0));
  EXPECT_EQ(mesh.vertices[3], Eigen::Vector3d(0, 0, 1e-3));
  EXPECT_EQ(mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 2, 3, 4}}));
  EXPECT_EQ(mesh.tetRegion, (std::vector<int>{2, -3}));
  EXPECT_EQ(raw.source.file, "s.ele");
  EXPECT_EQ(raw.source.tetPosition, (std::vector<int64_t>{lineOf(kEle1, "1 1 2 3 4"), lineOf(kEle1, "2 2 3 4 5")}));
  EXPECT_EQ(raw.source.tetFileId, (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(raw.source.vertexFileId, (std::vector<int64_t>{1, 2, 3, 4, 5}));
  EXPECT_EQ(raw.report.skippedCells, 0);
  EXPECT_TRUE(raw.report.warnings.empty());
}

TEST(TetGenRead, ZeroAndOneBasedLoadIdentically) {
  const RawMesh zero = parse(kNode0, kEle0);
  const RawMesh one = parse(kNode1, kEle1);
  test::expectSameMesh(one.mesh, zero.mesh);
  EXPECT_EQ(zero.source.vertexFileId, (std::vector<int64_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(zero.source.tetFileId, (std::vector<int64_t>{0, 1}));
}

TEST(TetGenRead, OptionalHeaderFieldsDefault) {
  const RawMesh raw = parse("4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "1\n1 1 2 3 4\n");
  EXPECT_EQ(raw.mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}}));
  EXPECT_EQ(raw.mesh.tetRegion, (std::vector<int>{0}));
}

TEST(TetGenRead, TenNodeTetsKeepTheirCornersAndWarnOnce) {
  std::string node = "10 3 0 0\n";
  for (int i = 1; i <= 10; ++i) node += std::to_string(i) + " " + std::to_string(i) + " 0 " + std::to_string(i % 3) + "\n";
  const std::string ele = "2 10 1\n1 1 2 3 4 5 6 7 8 9 10 1\n2 2 3 4 1 6 7 8 9 10 5 2\n";
  const RawMesh raw = parseTetGen(node, ele, "q.node", "q.ele");
  EXPECT_EQ(raw.mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 2, 3, 0}}));
  EXPECT_EQ(raw.mesh.tetRegion, (std::vector<int>{1, 2}));
  ASSERT_EQ(raw.report.warnings.size(), 1u);
  EXPECT_NE(raw.report.warnings[0].find("q.ele"), std::string::npos) << raw.report.warnings[0];

  const std::string bad = replaced(ele, "10 5 2", "10 11 2");  // edge nodes are checked too
  expectErrorAt(meshErrorOf([&] { parseTetGen(node, bad, "q.node", "q.ele"); }), "q.ele", lineOf(bad, "10 11 2"),
                "element 2: vertex index 11 is out of range [1, 10]");
}

TEST(TetGenRoundTrip, JitteredBoxBitExact) {
  const TetMesh mesh = test::jitteredBox(4);
  const auto [node, ele] = formatTetGen(mesh);
  test::expectSameMesh(mesh, parseTetGen(node, ele, "rt.node", "rt.ele").mesh);
}

TEST(TetGenRoundTrip, NoRegionsReadBackAsZero) {
  TetMesh mesh = test::jitteredBox(5);
  mesh.tetRegion.clear();
  const auto [node, ele] = formatTetGen(mesh);
  const TetMesh back = parseTetGen(node, ele, "rt.node", "rt.ele").mesh;
  EXPECT_EQ(back.tets, mesh.tets);
  EXPECT_EQ(back.tetRegion, std::vector<int>(mesh.tets.size(), 0));
}

TEST(TetGenWrite, RefusesMeshesThatWouldNotReadBack) {
  TetMesh mesh = test::jitteredBox(6);
  mesh.vertices[2].x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(formatTetGen(mesh), MeshError);
  mesh = test::jitteredBox(6);
  mesh.tets[0][0] = -1;
  EXPECT_THROW(formatTetGen(mesh), MeshError);
}

TEST(TetGenBadInput, VertexIndexOutOfRange) {
  const std::string ele = replaced(kEle1, "2 2 3 4 5", "2 2 3 4 6");
  expectErrorAt(errorOf(kNode1, ele), "s.ele", lineOf(ele, "2 2 3 4 6"), "element 2: vertex index 6 is out of range [1, 5]");
}

TEST(TetGenBadInput, EleBaseDiffersFromNodeBase) {
  expectErrorAt(errorOf(kNode1, kEle0), "s.ele", lineOf(kEle0, "0 0 1 2 3"), "vertex index 0 is out of range [1, 5]");
  expectErrorAt(errorOf(kNode0, kEle1), "s.ele", lineOf(kEle1, "2 2 3 4 5"), "vertex index 5 is out of range [0, 4]");
}

TEST(TetGenBadInput, NonNumericNonFiniteAndNonIntegralRegion) {
  std::string node = replaced(kNode1, "2 1.5 0 0", "2 nan 0 0");
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(node, "nan"), "x coordinate");
  node = replaced(kNode1, "5 1 1 1 2", "5 1 1 inf 2");
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(node, "inf"), "z coordinate");
  node = replaced(kNode1, "2 1.5 0 0 0.5 1", "2 1.5 0 0 0.5 yes");
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(node, "yes"), "'yes'");
  std::string ele = replaced(kEle1, "1 1 2 3 4", "1 1 2 three 4");
  expectErrorAt(errorOf(kNode1, ele), "s.ele", lineOf(ele, "three"), "'three'");
  for (const char* region : {"1.5", "nan", "1e300"}) {
    ele = replaced(kEle1, "2.0 0.25", std::string(region) + " 0.25");
    expectErrorAt(errorOf(kNode1, ele), "s.ele", lineOf(ele, region), "region attribute '" + std::string(region) + "'");
  }
}

TEST(TetGenBadInput, HugeCountFailsFast) {
  const std::string node = replaced(kNode1, "5 3 1 1", "99999999999 3 1 1");
  expectErrorAt(errorOf(node, kEle1), "s.node", 2, "99999999999");
  const std::string ele = replaced(kEle1, "2 4 2", "99999999999 4 2");
  expectErrorAt(errorOf(kNode1, ele), "s.ele", 1, "99999999999");
}

TEST(TetGenBadInput, TruncatedAnywhere) {
  test::expectEveryCutFails(kNode1, "s.node", [](std::string_view node) { parseTetGen(node, kEle1, "s.node", "s.ele"); });
  test::expectEveryCutFails(kEle1, "s.ele", [](std::string_view ele) { parseTetGen(kNode1, ele, "s.node", "s.ele"); });
}

TEST(TetGenBadInput, NumberingAndFieldCounts) {
  std::string node = replaced(kNode1, "1 0 0 0 0.5 1", "2 0 0 0 0.5 1");
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(kNode1, "1 0 0 0"), "the first vertex number must be 0 or 1");
  node = replaced(kNode1, "3 0 -2.25", "7 0 -2.25");
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(node, "7 0 -2.25"), "vertex number 7 is out of sequence");
  node = replaced(kNode1, "5 1 1 1 2 0", "5 1 1 1 2 0 9");
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(node, "5 1 1 1 2 0 9"), "vertex 5: expected 6 fields");
  node = replaced(kNode1, "2 1.5 0 0 0.5 1", "2 1.5 0 0 0.5");  // its marker would come from the next record
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(node, "2 1.5"), "vertex 2: expected 6 fields");
  node = replaced(kNode1, "5 3 1 1", "4 3 1 1");
  expectErrorAt(errorOf(node, kEle1), "s.node", lineOf(node, "5 1 1 1"), "unexpected '5'");
  node = replaced(kNode1, "5 3 1 1", "5 2 1 1");
  expectErrorAt(errorOf(node, kEle1), "s.node", 2, "dimension 2 is not supported");
  std::string ele = replaced(kEle1, "2 4 2", "2 5 2");
  expectErrorAt(errorOf(kNode1, ele), "s.ele", 1, "nodes per tetrahedron must be 4 or 10, found 5");
  ele = replaced(kEle1, "2 4 2", "2 4 2 9");
  expectErrorAt(errorOf(kNode1, ele), "s.ele", 1, "unexpected '9'");
  ele = replaced(kEle1, "2.0 0.25", "2.0");  // its last attribute would come from the next record
  expectErrorAt(errorOf(kNode1, ele), "s.ele", lineOf(ele, "1 1 2 3 4"), "element 1: expected 7 fields");
  ele = "1 4 1\n1 1 2 3\n4 2\n";  // one record split over two lines
  expectErrorAt(errorOf(kNode1, ele), "s.ele", 2, "element 1: expected 6 fields");
}

} // namespace
} // namespace quiver
