// Our PLY reader (formats/mesh/own_readers.h) through readSurfaceMemory, as the bake reads artists'
// files: one cube written by this test in ASCII and both binary byte orders, with LF and CRLF
// headers, reads back to the bits written; the files that broke Debian's Assimp 5.2.5 read right;
// Assimp's own PLY test models read as Assimp's own importer reads them (where it can); every
// malformed file is refused with the file and the line or byte named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "common/mesh_error.h"
#include "common/surface_check.h"
#include "formats/mesh/byte_cursor.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/read_surface.h"
#include "tests/formats/mesh/surface_test_support.h"

namespace quiver {
namespace {

// A unit cube with six quads, one vertex moved by `first` in x (so that a test can choose the
// first bytes of the binary data), and normals and texture coordinates per vertex.
struct Cube {
  std::vector<std::array<float, 3>> positions{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                             {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  std::vector<std::array<int, 4>> quads{{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
};

std::string header(const std::string& format, const std::string& eol) {
  std::string h;
  for (const char* line : {"ply", "comment made by ply_importer_test", "element vertex 8", "property float x",
                           "property float y", "property float z", "property uchar red", "property float s",
                           "property float t", "element edge 1", "property int vertex1", "property int vertex2",
                           "element face 6", "property list uchar int vertex_indices", "property list uchar float weights"}) {
    h += line + eol;
    if (std::string(line) == "ply") h += "format " + format + " 1.0" + eol;
  }
  return h + "end_header" + eol;
}

template <class T>
void put(std::string& out, T value, bool bigEndian) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (bigEndian == hostIsLittleEndian())
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  out.append(raw, sizeof(T));
}

std::string binaryCube(const Cube& c, bool bigEndian, const std::string& eol) {
  std::string out = header(bigEndian ? "binary_big_endian" : "binary_little_endian", eol);
  for (size_t v = 0; v < c.positions.size(); ++v) {
    for (float x : c.positions[v]) put(out, x, bigEndian);
    put<uint8_t>(out, 200, bigEndian);
    put(out, c.positions[v][0], bigEndian);
    put(out, c.positions[v][1], bigEndian);
  }
  put<int32_t>(out, 0, bigEndian), put<int32_t>(out, 1, bigEndian);
  for (const auto& q : c.quads) {
    put<uint8_t>(out, 4, bigEndian);
    for (int i : q) put<int32_t>(out, i, bigEndian);
    put<uint8_t>(out, 1, bigEndian), put(out, 0.5f, bigEndian);
  }
  return out;
}

std::string asciiCube(const Cube& c, const std::string& eol) {
  std::string out = header("ascii", eol);
  char line[200];
  for (const auto& p : c.positions) {
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g 200 %.9g %.9g", p[0], p[1], p[2], p[0], p[1]);
    out += line + eol;
  }
  out += "0 1" + eol;
  for (const auto& q : c.quads) out += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + " 1 0.5" + eol;
  return out;
}

SurfaceMesh read(const std::string& bytes, const std::string& name = "cube.ply") {
  return readSurfaceMemory(bytes.data(), bytes.size(), "ply", name);
}

// The welded positions are exactly the cube's corners, the faces close it (volume 1), and what is
// drawn keeps the texture coordinates written, s = x and t = y.
void expectCube(const SurfaceMesh& s, const Cube& c, const std::string& what) {
  ASSERT_EQ(s.positions.size(), 3 * c.positions.size()) << what;
  for (size_t v = 0; v < c.positions.size(); ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.positions[3 * v + k], double(c.positions[v][k])) << what << ": vertex " << v;
  const CheckedSurface checked = checkSurface(s.positions, s.triangles, what);
  EXPECT_EQ(checked.triangles.size(), 12u) << what;
  EXPECT_NEAR(checked.volume, 1.0, 1e-6) << what;
  ASSERT_EQ(s.render.uvs.size(), 2 * s.render.positions.size() / 3) << what;
  for (size_t v = 0; v < s.render.positions.size() / 3; ++v) {
    EXPECT_EQ(s.render.uvs[2 * v], s.render.positions[3 * v]) << what;
    EXPECT_EQ(s.render.uvs[2 * v + 1], s.render.positions[3 * v + 1]) << what;
  }
}

TEST(PlyReader, OneCubeReadsBackInEveryEncodingAndLineEnd) {
  const Cube cube;
  for (const std::string eol : {"\n", "\r\n"}) {
    const std::string crlf = eol == "\n" ? "LF" : "CRLF";
    expectCube(read(asciiCube(cube, eol)), cube, "ascii, " + crlf);
    expectCube(read(binaryCube(cube, false, eol)), cube, "little endian, " + crlf);
    expectCube(read(binaryCube(cube, true, eol)), cube, "big endian, " + crlf);
  }
}

TEST(PlyReader, BinaryDataThatBeginsWithALineEndByteReadsRight) {
  // Debian's Assimp 5.2.5 took this 0x0A for the header's line end, read every value one byte
  // late, and aborted the process in its triangulation (an ai_assert).
  Cube cube;
  const unsigned char bits[4] = {0x0a, 0x00, 0x80, 0x3f};  // little endian: 1.0000012f
  std::memcpy(&cube.positions[0][0], bits, 4);
  const std::string bytes = binaryCube(cube, false, "\n");
  ASSERT_EQ(bytes[header("binary_little_endian", "\n").size()], '\n');
  const SurfaceMesh s = read(bytes);
  ASSERT_EQ(s.positions.size(), 24u);
  EXPECT_EQ(s.positions[0], double(cube.positions[0][0]));
}

TEST(PlyReader, TriangleStripsBecomeTrianglesThatWindAlike) {
  // Two unit squares, z = 0 and z = 1, as strips 0 1 3 2 and 4 5 7 6 in one list, and a third
  // strip whose one triangle is degenerate and dropped.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
      "13 0 1 3 2 -1 4 5 7 6 -1 0 0 1\n";
  const SurfaceMesh s = read(ply, "strips.ply");
  const std::vector<int> expected = {0, 1, 3, 3, 1, 2, 4, 5, 7, 7, 5, 6};  // every other one turned
  EXPECT_EQ(s.triangles, expected);
  // All wind alike: each triangle's normal points along +z.
  for (size_t t = 0; t < s.triangles.size(); t += 3) {
    const auto at = [&](int k, int c) { return s.positions[3 * s.triangles[t + k] + c]; };
    const double nz = (at(1, 0) - at(0, 0)) * (at(2, 1) - at(0, 1)) - (at(1, 1) - at(0, 1)) * (at(2, 0) - at(0, 0));
    EXPECT_GT(nz, 0) << "triangle " << t / 3;
  }
}

TEST(PlyReader, AssimpsTestModelsReadAsAssimpsOwnImporterReadsThem) {
  const std::filesystem::path folder = "/usr/share/assimp/models/PLY";
  if (!std::filesystem::exists(folder)) GTEST_SKIP() << "Debian's assimp-testmodels is not installed: " << folder;
  int compared = 0;
  for (const char* name : {"cube.ply", "cube_binary.ply", "cube_uv.ply", "float-color.ply", "Wuson.ply", "pond.0.ply"})
    if (std::filesystem::exists(folder / name)) compared += test::expectReadsAsAssimpsOwnImporter((folder / name).string());
  EXPECT_GE(compared, 5);  // pond.0.ply, a truncated point cloud, neither reads
}

void expectRefused(const std::string& bytes, const std::string& expected) {
  test::expectSurfaceRefused(bytes, "ply", "bad.ply", expected);
}

TEST(PlyReader, MalformedFilesAreRefusedNamingTheLineOrByte) {
  const Cube cube;
  const std::string good = binaryCube(cube, false, "\n");
  const size_t body = header("binary_little_endian", "\n").size();
  const std::string ascii = asciiCube(cube, "\n");

  // A face list counting 200 million indices: Assimp walked it for seconds and gigabytes.
  std::string huge = good;
  const size_t firstFace = body + 8 * 21 + 8;
  ASSERT_EQ(huge[firstFace], 4);
  huge[firstFace] = '\xff';
  expectRefused(huge, "byte " + std::to_string(firstFace) + ": the list vertex_indices counts 255 items, more than the bytes left");
  expectRefused(test::edited(ascii, "4 0 3 2 1", "200000000 0 3 2 1"), ":27: the list vertex_indices counts 200000000 items");

  expectRefused(good.substr(0, good.size() - 3), "the list weights counts 1 items, more than the bytes left");
  expectRefused(good.substr(0, good.size() - 5), "unexpected end of file while reading weights");
  expectRefused(test::edited(ascii, "4 0 3 2 1", "4 0 3 2 8"), ":27: face 0: vertex index 8 is out of range [0, 8)");
  // Found by fuzz.surface: a value no integer type holds, in the message.
  expectRefused(test::edited(ascii, "4 0 3 2 1", "4 0 3 2 1" + std::string(91, '0')),
                ":27: face 0: vertex index 1e+91 is out of range [0, 8)");
  expectRefused(test::edited(ascii, "4 0 3 2 1", "4 0 3 2 1.5"), ":27: vertex_indices 1.5");

  const std::string noEnd = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n";
  expectRefused(noEnd, "no end_header line");
  expectRefused("PLY\n" + ascii.substr(4), "bad.ply:1: not a PLY file");
  expectRefused(test::edited(ascii, "property float y", "property real y"), ":6: expected 'property TYPE NAME'");
  expectRefused(test::edited(ascii, "list uchar int", "list float int"), "(a list's count type integral)");
  expectRefused(test::edited(ascii, "4 0 3 2 1", "-1 0 3 2 1"), ":27: the list vertex_indices counts -1 items");
  expectRefused(test::edited(ascii, "list uchar int", "list uchar float"), ":17: the face element's vertex_indices list must have an integer type");
  std::string binaryOutOfRange = good;  // named at the index's own first byte
  binaryOutOfRange[firstFace + 1 + 4 * 3] = 8;
  expectRefused(binaryOutOfRange, "byte " + std::to_string(firstFace + 1 + 4 * 3) + ": face 0: vertex index 8 is out of range");
  expectRefused(test::edited(ascii, "0 0 0 200", "1e39 0 0 200"), ":18: vertex 0: coordinate 1e+39 is not a finite float");
  expectRefused("ply\nformat ascii 1.0\nproperty float x\nend_header\n", ":3: a property before any element");
  expectRefused("ply\nformat ascii 1.0\nelement vertex 3000000000\nproperty float x\nend_header\n", ":3: expected 'element NAME COUNT'");
  // Counts a file cannot hold allocate nothing: reading stops at the file's end.
  expectRefused("ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\nproperty float y\nproperty float z\n"
                "end_header\n0 0 0\n", "unexpected end of file while reading x");
  expectRefused("ply\nformat ascii 2.0\nend_header\n", ":2: expected 'format ascii");
  expectRefused("ply\nelement face 0\nend_header\n", "no format line");
  expectRefused("ply\nformat ascii 1.0\nelement face 0\nend_header\n", "no vertex element");
  expectRefused("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n", "lacks one of the properties x, y, z");
  expectRefused("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
                "no face of three or more vertices");
}

} // namespace
} // namespace quiver
