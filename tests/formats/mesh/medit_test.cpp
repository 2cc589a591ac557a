// Medit .mesh reader and writer: hand-written samples, round trips and bad input.
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

// Two tets sharing a face, among sections Quiver skips: 2 edges + 3 triangles + 1 hexahedron are
// elements (6 skipped cells); Corners, Normals and NormalAtVertices are not.
const std::string kSample = R"(# A hand-written Medit file.
MeshVersionFormatted 2
Dimension
3
# x y z ref
Vertices
5
0 0 0 1
1.5 0 0 1
0 -2.25 0 1
0 0 1e-3 2
1 1 1 2
Edges
2
1 2 0
2 3 0
triangles
3
1 2 3 5
1 2 4 5
2 3 5 5
Corners 1 1
Normals
1
0 0 1
NormalAtVertices
1
1 1
Hexahedra
1
1 2 3 4 5 1 2 3 9
TETRAHEDRA
2
1 2 3 4 7   # a comment after a record
2 3 4 5 -3
End
)";

RawMesh parse(std::string_view text, const std::string& file = "sample.mesh") { return parseMedit(text, file); }

std::string errorOf(const std::string& text) {
  return meshErrorOf([&] { parse(text, "bad.mesh"); });
}

TEST(MeditRead, SampleWithSkippedSectionsCommentsAndAnyCase) {
  RawMesh raw = parse(kSample);
  const TetMesh& mesh = raw.mesh;
  ASSERT_EQ(mesh.vertexCount(), 5);
  EXPECT_EQ(mesh.vertices[1], Eigen::Vector3d(1.5, 0, 0));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3d(0, -2.25, 0));
  EXPECT_EQ(mesh.vertices[3], Eigen::Vector3d(0, 0, 1e-3));
  EXPECT_EQ(mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 2, 3, 4}}));
  EXPECT_EQ(mesh.tetRegion, (std::vector<int>{7, -3}));

  EXPECT_EQ(raw.source.file, "sample.mesh");
  EXPECT_EQ(raw.source.positionKind, SourcePositionKind::Line);
  EXPECT_EQ(raw.source.tetPosition,
            (std::vector<int64_t>{lineOf(kSample, "1 2 3 4 7"), lineOf(kSample, "2 3 4 5 -3")}));
  EXPECT_EQ(raw.source.tetFileId, (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(raw.source.vertexFileId, (std::vector<int64_t>{1, 2, 3, 4, 5}));

  EXPECT_EQ(raw.report.skippedCells, 6);
  ASSERT_EQ(raw.report.warnings.size(), 1u);
  EXPECT_NE(raw.report.warnings[0].find("sample.mesh"), std::string::npos) << raw.report.warnings[0];
}

TEST(MeditRead, OnlyTetsNoWarning) {
  RawMesh raw = parse("MeshVersionFormatted 1 Dimension 3 Vertices 4 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 0 "
                      "Tetrahedra 1 1 2 3 4 0 End");
  EXPECT_EQ(raw.mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}}));
  EXPECT_EQ(raw.report.skippedCells, 0);
  EXPECT_TRUE(raw.report.warnings.empty());
}

TEST(MeditRoundTrip, JitteredBoxBitExact) {
  const TetMesh mesh = test::jitteredBox(1);
  test::expectSameMesh(mesh, parse(formatMedit(mesh)).mesh);
}

TEST(MeditRoundTrip, NoRegionsReadBackAsZero) {
  TetMesh mesh = test::jitteredBox(2);
  mesh.tetRegion.clear();
  const TetMesh back = parse(formatMedit(mesh)).mesh;
  EXPECT_EQ(back.tets, mesh.tets);
  EXPECT_EQ(back.tetRegion, std::vector<int>(mesh.tets.size(), 0));
}

TEST(MeditWrite, RefusesMeshesThatWouldNotReadBack) {
  TetMesh mesh = test::jitteredBox(3);
  mesh.vertices[4].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(formatMedit(mesh), MeshError);
  mesh = test::jitteredBox(3);
  mesh.tetRegion.pop_back();
  EXPECT_THROW(formatMedit(mesh), MeshError);
  mesh = test::jitteredBox(3);
  mesh.tets[5][2] = mesh.vertexCount();
  EXPECT_THROW(formatMedit(mesh), MeshError);
}

TEST(MeditBadInput, VertexIndexOutOfRange) {
  for (const char* record : {"1 2 3 6 7", "0 2 3 4 7"}) {
    const std::string text = replaced(kSample, "1 2 3 4 7", record);
    expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, record), "element 1: vertex index");
  }
  const std::string text = replaced(kSample, "2 3 4 5 -3", "2 3 4 -5 -3");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "2 3 4 -5"), "element 2: vertex index -5 is out of range [1, 5]");
}

TEST(MeditBadInput, NonNumericField) {
  std::string text = replaced(kSample, "1.5 0 0 1", "1.5 zero 0 1");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "zero"), "zero");
  text = replaced(kSample, "2 3 4 5 -3", "2 3 4 5 x");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "5 x"), "reference");
  text = replaced(kSample, "2 3 0", "2 3.5 0");  // a skipped section is still checked
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "3.5"), "Edges");
}

TEST(MeditBadInput, NonFiniteCoordinate) {
  for (const char* value : {"nan", "inf", "-inf", "1e999"}) {
    const std::string text = replaced(kSample, "1.5 0 0 1", std::string("1.5 0 ") + value + " 1");
    const std::string message = errorOf(text);
    expectErrorAt(message, "bad.mesh", lineOf(text, value), "z coordinate");
  }
}

TEST(MeditBadInput, HugeCountFailsFast) {
  expectErrorAt(errorOf("MeshVersionFormatted 2\nDimension 3\nVertices\n99999999999\n0 0 0 0\nEnd\n"), "bad.mesh", 4,
                "99999999999");
  expectErrorAt(errorOf(replaced(kSample, "Hexahedra\n1\n", "Hexahedra\n123456789012345\n")), "bad.mesh",
                lineOf(kSample, "Hexahedra") + 1, "123456789012345");
}

TEST(MeditBadInput, TruncatedAnywhere) {
  test::expectEveryCutFails(kSample, "cut.mesh", [](std::string_view text) { parseMedit(text, "cut.mesh"); });
  expectErrorAt(errorOf(replaced(kSample, "End\n", "")), "bad.mesh", lineOf(kSample, "End"), "'End'");
}

TEST(MeditBadInput, StructureErrors) {
  expectErrorAt(errorOf(replaced(kSample, "Dimension\n3", "Dimension\n2")), "bad.mesh", lineOf(kSample, "Dimension") + 1,
                "Dimension 2 is not supported");
  expectErrorAt(errorOf(replaced(kSample, "Corners", "Crackers")), "bad.mesh", lineOf(kSample, "Corners"),
                "unsupported section 'Crackers'");
  expectErrorAt(errorOf(replaced(kSample, "MeshVersionFormatted 2", "MeshVersionFormatted 7")), "bad.mesh", 2,
                "MeshVersionFormatted");
  expectErrorAt(errorOf("Dimension 3\nEnd\n"), "bad.mesh", 1, "expected 'MeshVersionFormatted'");
  expectErrorAt(errorOf("MeshVersionFormatted 2\nDimension 3\nTetrahedra 0\nEnd\n"), "bad.mesh", 3,
                "'Tetrahedra' before 'Vertices'");
  expectErrorAt(errorOf("MeshVersionFormatted 2\nVertices 0\nEnd\n"), "bad.mesh", 2, "'Vertices' before 'Dimension'");
  expectErrorAt(errorOf(replaced(kSample, "End", "Vertices 0\nEnd")), "bad.mesh", lineOf(kSample, "End"),
                "a second 'Vertices' section");
}

TEST(MeditBadInput, BinaryMeshbIsRefused) {
  const std::string meshb("\x01\x00\x00\x00\x02\x00\x00\x00\x03\x00\x00\x00\x03\x00\x00\x00", 16);
  const std::string message = errorOf(meshb);
  EXPECT_NE(message.find("bad.mesh"), std::string::npos) << message;
  EXPECT_NE(message.find("binary"), std::string::npos) << message;
}

} // namespace
} // namespace quiver
