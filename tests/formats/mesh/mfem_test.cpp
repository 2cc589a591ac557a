// MFEM mesh v1.0 reader: the shared beam, a hand-written sample and bad input.
#include <algorithm>
#include <fstream>
#include <sstream>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "formats/mesh/read_mesh.h"
#include "tests/formats/mesh/text_mesh_test_support.h"
#include "tests/support/test_support.h"

namespace quiver {
namespace {

using test::expectErrorAt;
using test::lineOf;
using test::meshErrorOf;
using test::replaced;

// The unit cube's 8 corners; two tets among a cube and a triangle that Quiver skips.
const std::string kSample = R"(MFEM mesh v1.0

# hand-written: two tets, one cube and one (stray) triangle element
dimension
3

elements
4
3 4 0 1 3 7
5 4 0 1 7 5
1 5 0 1 3 2 4 5 7 6
2 2 0 1 3

# boundary elements are read and ignored
boundary
3
1 2 0 1 3
1 3 0 1 5 4
2 1 0 1

vertices
8
3
0 0 0
1 0 0
0 1 0
1 1 0
0 0 1
1 0 1
0 1 1
1 1 1
)";

std::string errorOf(const std::string& text) {
  return meshErrorOf([&] { parseMfem(text, "bad.mesh"); });
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(MfemRead, SampleSkipsOtherGeometries) {
  const RawMesh raw = parseMfem(kSample, "sample.mesh");
  const TetMesh& mesh = raw.mesh;
  ASSERT_EQ(mesh.vertexCount(), 8);
  EXPECT_EQ(mesh.vertices[3], Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(mesh.vertices[5], Eigen::Vector3d(1, 0, 1));
  EXPECT_EQ(mesh.tets, (std::vector<Tet>{{0, 1, 3, 7}, {0, 1, 7, 5}}));
  EXPECT_EQ(mesh.tetRegion, (std::vector<int>{3, 5}));
  EXPECT_EQ(raw.source.file, "sample.mesh");
  EXPECT_EQ(raw.source.tetPosition,
            (std::vector<int64_t>{lineOf(kSample, "3 4 0 1 3 7"), lineOf(kSample, "5 4 0 1 7 5")}));
  EXPECT_EQ(raw.source.tetFileId, (std::vector<int64_t>{1, 2}));  // ordinals among all 4 elements
  EXPECT_EQ(raw.source.vertexFileId, (std::vector<int64_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(raw.report.skippedCells, 2);
  ASSERT_EQ(raw.report.warnings.size(), 1u);
  EXPECT_NE(raw.report.warnings[0].find("sample.mesh"), std::string::npos) << raw.report.warnings[0];
}

TEST(MfemRead, Version12WithEndTagReadsTheSame) {
  const std::string v12 = replaced(kSample, "MFEM mesh v1.0", "MFEM mesh v1.2") + "\nmfem_mesh_end\n";
  const TetMesh mesh = parseMfem(v12, "v12.mesh").mesh;
  test::expectSameMesh(parseMfem(kSample, "v10.mesh").mesh, mesh);
  expectErrorAt(errorOf(replaced(v12, "mfem_mesh_end", "")), "bad.mesh", lineOf(v12, "mfem_mesh_end") + 1,
                "mfem_mesh_end");
}

TEST(MfemBeam, SharedBeamMatchesItsTextAndVolume) {
  QUIVER_REQUIRE_SHARED_MESH(path, "mfem_beam-tet.mesh");
  const std::string text = readText(path);
  const RawMesh raw = parseMfem(text, path);
  const TetMesh& mesh = raw.mesh;

  // The README's description: 36 vertices, 48 tets, attributes 1 and 2 on 24 tets each.
  EXPECT_EQ(mesh.vertexCount(), 36);
  ASSERT_EQ(mesh.tetCount(), 48);
  EXPECT_EQ(std::count(mesh.tetRegion.begin(), mesh.tetRegion.end(), 1), 24);
  EXPECT_EQ(std::count(mesh.tetRegion.begin(), mesh.tetRegion.end(), 2), 24);
  EXPECT_EQ(raw.report.skippedCells, 0);
  EXPECT_TRUE(raw.report.warnings.empty());

  // The file's own text: element t is line "elements" + 2 + t and reads "attribute 4 v0 v1 v2 v3".
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  const auto elements = std::find(lines.begin(), lines.end(), "elements");
  ASSERT_NE(elements, lines.end());
  EXPECT_EQ(std::stoi(elements[1]), mesh.tetCount());
  const auto vertices = std::find(lines.begin(), lines.end(), "vertices");
  ASSERT_NE(vertices, lines.end());
  EXPECT_EQ(std::stoi(vertices[1]), mesh.vertexCount());
  const int firstElementLine = static_cast<int>(elements - lines.begin()) + 3;
  for (int t = 0; t < mesh.tetCount(); ++t) {
    EXPECT_EQ(raw.source.tetPosition[t], firstElementLine + t);
    EXPECT_EQ(raw.source.tetFileId[t], t + 1);
    std::istringstream fields(elements[2 + t]);
    int attribute = 0, geometry = 0;
    Tet tet{};
    fields >> attribute >> geometry >> tet[0] >> tet[1] >> tet[2] >> tet[3];
    EXPECT_EQ(attribute, mesh.tetRegion[t]) << "tet " << t;
    EXPECT_EQ(geometry, 4) << "tet " << t;
    EXPECT_EQ(tet, mesh.tets[t]) << "tet " << t;
  }

  // The analytic box [0,8]x[0,1]x[0,1]: total |volume| 8.
  double volume = 0;
  Eigen::Vector3d lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Eigen::Vector3d& x : mesh.vertices) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  for (const Tet& tet : mesh.tets) {
    Eigen::Matrix3d edges;
    for (int k = 0; k < 3; ++k) edges.col(k) = mesh.vertices[tet[k + 1]] - mesh.vertices[tet[0]];
    volume += std::abs(edges.determinant()) / 6;
  }
  EXPECT_NEAR(volume, 8.0, 1e-12);
  EXPECT_EQ(lo, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(hi, Eigen::Vector3d(8, 1, 1));

  test::expectEveryCutFails(text, path, [&](std::string_view cut) { parseMfem(cut, path); });
}

TEST(MfemBadInput, VertexIndexOutOfRange) {
  std::string text = replaced(kSample, "5 4 0 1 7 5", "5 4 0 1 8 5");  // checked once the 8 vertices are read
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "5 4 0 1 8 5"), "element 2: vertex index 8 is out of range [0, 7]");
  text = replaced(kSample, "5 4 0 1 7 5", "5 4 0 -1 7 5");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "5 4 0 -1 7 5"), "element 2: vertex index -1");
}

TEST(MfemBadInput, NonNumericAndNonFinite) {
  std::string text = replaced(kSample, "3 4 0 1 3 7", "3 4 0 uno 3 7");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "uno"), "'uno'");
  text = replaced(kSample, "1 1 1\n", "1 nan 1\n");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "nan"), "y coordinate");
  text = replaced(kSample, "0 1 1\n", "0 1 -inf\n");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "-inf"), "z coordinate");
  text = replaced(kSample, "2 2 0 1 3", "2 9 0 1 3");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "2 9 0 1 3"), "geometry type 9");
}

TEST(MfemBadInput, HugeCountFailsFast) {
  const std::string text = replaced(kSample, "elements\n4\n", "elements\n99999999999\n");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "99999999999"), "99999999999");
}

TEST(MfemBadInput, TruncatedAnywhere) {
  test::expectEveryCutFails(kSample, "cut.mesh", [](std::string_view text) { parseMfem(text, "cut.mesh"); });
}

TEST(MfemBadInput, UnsupportedVariants) {
  expectErrorAt(errorOf(replaced(kSample, "MFEM mesh v1.0", "MFEM NC mesh v1.0")), "bad.mesh", 1, "not supported");
  expectErrorAt(errorOf(replaced(kSample, "dimension\n3", "dimension\n2")), "bad.mesh", lineOf(kSample, "dimension") + 1,
                "dimension 2 is not supported");
  std::string text = replaced(kSample, "8\n3\n0 0 0", "8\n2\n0 0 0");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "vertices") + 2, "vertex dimension 2");
  text = replaced(kSample, "8\n3\n0 0 0", "8\n\nnodes\nFiniteElementSpace\nFiniteElementCollection: H1_3D_P2\n0 0 0");
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "nodes"), "curved MFEM meshes");
  text = kSample + "extra 1 2 3\n";
  expectErrorAt(errorOf(text), "bad.mesh", lineOf(text, "extra"), "unexpected 'extra'");
  expectErrorAt(errorOf(replaced(kSample, "boundary\n", "")), "bad.mesh", lineOf(kSample, "boundary\n3"),
                "expected 'boundary'");
}

} // namespace
} // namespace quiver
