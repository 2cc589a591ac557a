// Our OFF reader (formats/mesh/own_readers.h) through readSurfaceMemory: one cube written by this
// test with each prefix of the header keyword reads back to the corners written; Assimp's own OFF
// test models read as Assimp's own importer reads them; malformed files, among them the one on
// which Debian's Assimp 5.2.5 asked for more than 2 GB, are refused with the file and line named.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/mesh_error.h"
#include "common/surface_check.h"
#include "formats/mesh/read_surface.h"
#include "tests/formats/mesh/surface_test_support.h"

namespace quiver {
namespace {

const char* const kCorners[8] = {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"};
const char* const kQuads[6] = {"4 0 3 2 1", "4 4 5 6 7", "4 0 1 5 4", "4 2 3 7 6", "4 1 2 6 5", "4 0 4 7 3"};

// The cube: `header` (keyword and counts), each corner followed by `perVertex`, each face by
// `perFace`.
std::string cube(const std::string& header, const std::string& perVertex = "", const std::string& perFace = "",
                 const std::string& eol = "\n") {
  std::string out = header + eol;
  for (const char* c : kCorners) out += std::string(c) + perVertex + eol;
  for (const char* q : kQuads) out += std::string(q) + perFace + eol;
  return out;
}

SurfaceMesh read(const std::string& bytes, const std::string& name = "cube.off") {
  return readSurfaceMemory(bytes.data(), bytes.size(), "off", name);
}

void expectCube(const SurfaceMesh& s, const std::string& what) {
  ASSERT_EQ(s.positions.size(), 24u) << what;
  for (int v = 0; v < 8; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.positions[3 * v + k], double(kCorners[v][2 * k] - '0')) << what << ": vertex " << v;
  const CheckedSurface checked = checkSurface(s.positions, s.triangles, what);
  EXPECT_EQ(checked.triangles.size(), 12u) << what;
  EXPECT_NEAR(checked.volume, 1.0, 1e-12) << what;
}

TEST(OffReader, OneCubeReadsBackWithEveryHeaderKeyword) {
  expectCube(read(cube("OFF\n8 6 12")), "OFF");
  expectCube(read(cube("OFF 8 6 12")), "keyword and counts on one line");
  expectCube(read(cube("8 6 12")), "no keyword");
  expectCube(read(cube("OFF\n8 6")), "no edge count");
  expectCube(read(cube("# a cube\nOFF # the keyword\n\n8 6 12", " # a corner", "", "\r\n")), "comments, blank lines, CRLF");
  expectCube(read(cube("COFF\n8 6 12", " 0.5 0.25 0.125 1", " 255 0 0")), "COFF: colours skipped");
  expectCube(read(cube("nOFF\n3\n8 6 12")), "nOFF, dimension 3");
  const SurfaceMesh normals = read(cube("NOFF\n8 6 12", " 0 0 1"));
  expectCube(normals, "NOFF");
  for (size_t i = 2; i < normals.render.normals.size(); i += 3) EXPECT_EQ(normals.render.normals[i], 1.0f);
  const SurfaceMesh uv = read(cube("STCOFF\n8 6 12", " 0.5 0.5 0.5 0.25 0.75"));
  expectCube(uv, "STCOFF: the line's last two numbers");
  ASSERT_EQ(uv.render.uvs.size(), 2 * uv.render.positions.size() / 3);
  EXPECT_EQ(uv.render.uvs[0], 0.25f);
  EXPECT_EQ(uv.render.uvs[1], 0.75f);
  // 4OFF: homogeneous coordinates, each corner written doubled with w = 2.
  std::string homogeneous = "4OFF\n8 6 12\n";
  for (const char* c : kCorners)
    homogeneous += std::to_string(2 * (c[0] - '0')) + " " + std::to_string(2 * (c[2] - '0')) + " " + std::to_string(2 * (c[4] - '0')) + " 2\n";
  for (const char* q : kQuads) homogeneous += std::string(q) + "\n";
  expectCube(read(homogeneous), "4OFF");
}

TEST(OffReader, AssimpsTestModelsReadAsAssimpsOwnImporterReadsThem) {
  const std::filesystem::path folder = "/usr/share/assimp/models/OFF";
  if (!std::filesystem::exists(folder)) GTEST_SKIP() << "Debian's assimp-testmodels is not installed: " << folder;
  int compared = 0;
  for (const char* name : {"Cube.off", "Wuson.off"})
    if (std::filesystem::exists(folder / name)) compared += test::expectReadsAsAssimpsOwnImporter((folder / name).string());
  EXPECT_EQ(compared, 2);
}

void expectRefused(const std::string& bytes, const std::string& expected) {
  test::expectSurfaceRefused(bytes, "off", "bad.off", expected);
}

TEST(OffReader, MalformedFilesAreRefusedNamingTheLine) {
  // Found by fuzz.surface: Assimp's importer took the face count modulo 2^32 and allocated that many.
  expectRefused("OFF1 1000000000000000000000000000000\x83" "0000\n 01\n4\n", "bad.off:1: expected a whole number for the vertices, found 'OFF1'");
  expectRefused("OFF\n3 1000000000000000000000000000000 0\n", "bad.off:2: expected a whole number for the faces");
  // Counts a file cannot hold allocate nothing: reading stops at its end.
  expectRefused("OFF\n4 7777777777776 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n", "unexpected end of file while reading a face");
  expectRefused(test::edited(cube("OFF\n8 6 12"), "4 0 3 2 1", "4 0 3 2 8"), "bad.off:11: face 0: vertex index 8 is out of range [0, 8)");
  expectRefused(test::edited(cube("OFF\n8 6 12"), "4 0 3 2 1", "5 0 3 2 1"), "bad.off:11: face 0 counts 5 vertices; its line lists 4 numbers");
  expectRefused(test::edited(cube("NOFF\n8 6 12", " 0 0 1"), "0 0 0 0 0 1", "0 0 0 0 0"), "bad.off:3: vertex 0: 5 numbers, fewer than the 6 the header's keyword asks for");
  expectRefused("XOFF\n8 6 12\n", "bad.off:1: unknown header keyword 'XOFF'");
  expectRefused("nOFF\n4\n8 6 12\n", "bad.off:2: a dimension of 4; 1, 2 or 3 are read here");
  expectRefused("nOFF\n4294967299\n8 6 12\n", "bad.off:2: a dimension of 4294967299");
  expectRefused("OFF\n8\n", "bad.off:2: expected the counts 'VERTICES FACES [EDGES]'");
  expectRefused("OFF\n", "unexpected end of file while reading the counts");
  expectRefused(test::edited(cube("OFF\n8 6 12"), "1 0 0", "1 zero 0"), "bad.off:4: expected a number for a coordinate, found 'zero'");
  expectRefused(test::edited(cube("OFF\n8 6 12"), "1 0 0", "1e39 0 0"), "bad.off:4: vertex 1: a coordinate is not a finite float");
  expectRefused("4OFF\n3 1 0\n0 0 0 0\n1 0 0 1\n0 1 0 1\n3 0 1 2\n", "bad.off:3: vertex 0: a coordinate is not a finite float");
}

} // namespace
} // namespace quiver
