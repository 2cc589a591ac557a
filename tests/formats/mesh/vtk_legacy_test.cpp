// VTK legacy reader and writer: the shared meshes, hand-written ASCII, BINARY and VTK 5.1 samples,
// a write-read round trip and bad input.
#include <algorithm>
#include <charconv>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "formats/mesh/byte_cursor.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/write_mesh.h"
#include "tests/formats/mesh/text_mesh_test_support.h"
#include "tests/support/test_support.h"

namespace quiver {
namespace {

using test::expectErrorAt;
using test::lineOf;
using test::meshErrorOf;
using test::replaced;

// Eight cube corners and two mid-edge points; two tets among a triangle and a quadratic tet, and
// every kind of data a reader has to step over.
const std::string kSample = R"(# vtk DataFile Version 3.0
hand-written: two tets of the unit cube, a triangle and a quadratic tet
ASCII
DATASET UNSTRUCTURED_GRID
FIELD FieldData 2
TIME 1 1 double
0.5
labels 1 2 string
first%20label
second
POINTS 10 float
0 0 0  1 0 0  0 1 0
1 1 0  0 0 1  1 0 1
0 1 1  1 1 1  0.5 0 0
0.5 0.5 0
CELLS 4 25
4 0 1 3 7
3 0 1 2
4 0 1 7 5
10 0 1 2 4 8 9 8 8 8 8
CELL_TYPES 4
10
5
10
24
CELL_DATA 4
SCALARS pressure float 1
LOOKUP_TABLE default
1.5 2.5 3.5 4.5
METADATA
INFORMATION 0

SCALARS MaterialIds int
LOOKUP_TABLE default
7 8 9 10
VECTORS velocity double
1 2 3  4 5 6  7 8 9  10 11 12
POINT_DATA 10
SCALARS temperature double 2
LOOKUP_TABLE colours
1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20
LOOKUP_TABLE colours 2
0 0 0 1  1 1 1 1
COLOR_SCALARS rgb 3
0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
TEXTURE_COORDINATES uv 2 float
0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
FIELD extra 1
flags 1 10 bit
0 1 0 1 0 1 0 1 0 1
)";

// The smallest valid file: the truncation test cuts it everywhere.
const std::string kMinimal = R"(# vtk DataFile Version 2.0
one tet
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 4 double
0 0 0 1 0 0 0 1 0 0 0 1
CELLS 1 5
4 0 1 2 3
CELL_TYPES 1
10
)";

std::string errorOf(const std::string& text) {
  return meshErrorOf([&] { parseVtkLegacy(text, "bad.vtk"); });
}

TEST(VtkLegacyRead, SampleKeepsTetsAndSkipsEverythingElse) {
  const RawMesh raw = parseVtkLegacy(kSample, "sample.vtk");
  const TetMesh& mesh = raw.mesh;
  ASSERT_EQ(mesh.vertexCount(), 10);
  EXPECT_EQ(mesh.vertices[7], Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(mesh.vertices[9], Eigen::Vector3d(0.5, 0.5, 0));
  EXPECT_EQ(mesh.tets, (std::vector<Tet>{{0, 1, 3, 7}, {0, 1, 7, 5}}));
  EXPECT_EQ(mesh.tetRegion, (std::vector<int>{7, 9}));  // MaterialIds of cells 0 and 2
  EXPECT_EQ(raw.source.file, "sample.vtk");
  EXPECT_EQ(raw.source.positionKind, SourcePositionKind::Line);
  EXPECT_EQ(raw.source.tetPosition,
            (std::vector<int64_t>{lineOf(kSample, "4 0 1 3 7"), lineOf(kSample, "4 0 1 7 5")}));
  EXPECT_EQ(raw.source.tetFileId, (std::vector<int64_t>{0, 2}));
  EXPECT_EQ(raw.source.vertexFileId, (std::vector<int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(raw.report.skippedCells, 2);
  ASSERT_EQ(raw.report.warnings.size(), 1u);
  for (const char* part : {"sample.vtk", "1 VTK_TRIANGLE", "1 VTK_QUADRATIC_TETRA"})
    EXPECT_NE(raw.report.warnings[0].find(part), std::string::npos) << raw.report.warnings[0];
}

TEST(VtkLegacyRead, RegionFromFieldArrayAndNoRegion) {
  // meshio writes cell data as FIELD arrays.
  std::string text =
      kMinimal + "CELL_DATA 1\nFIELD FieldData 2\ngmsh:geometrical 1 1 int\n5\ngmsh:physical 1 1 int\n42\n";
  EXPECT_EQ(parseVtkLegacy(text, "field.vtk").mesh.tetRegion, (std::vector<int>{42}));
  EXPECT_EQ(parseVtkLegacy(kMinimal, "plain.vtk").mesh.tetRegion, (std::vector<int>{0}));
  // A region-named array of floats cannot give regions: ignored, with a warning.
  text = kMinimal + "CELL_DATA 1\nSCALARS material float\nLOOKUP_TABLE default\n3.5\n";
  const RawMesh raw = parseVtkLegacy(text, "float.vtk");
  EXPECT_EQ(raw.mesh.tetRegion, (std::vector<int>{0}));
  ASSERT_EQ(raw.report.warnings.size(), 1u);
  EXPECT_NE(raw.report.warnings[0].find("float.vtk:" + std::to_string(lineOf(text, "SCALARS material"))),
            std::string::npos) << raw.report.warnings[0];
}

TEST(VtkLegacyRead, Vtk51OffsetsAndConnectivity) {
  const std::string text = R"(# vtk DataFile Version 5.1
VTK 5.1 cell layout
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 6 double
0 0 0 1 0 0 0 1 0 0 0 1 1 1 1 2 2 2
CELLS 4 11
OFFSETS vtktypeint64
0 4 7 11
CONNECTIVITY vtktypeint32
0 1 2 3 0 1 2
1 2 3 4
CELL_TYPES 3
10 5 10
CELL_DATA 3
SCALARS CellEntityIds long 1
LOOKUP_TABLE default
11 12 13
)";
  const RawMesh raw = parseVtkLegacy(text, "v51.vtk");
  EXPECT_EQ(raw.mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 2, 3, 4}}));
  EXPECT_EQ(raw.mesh.tetRegion, (std::vector<int>{11, 13}));
  // A cell is placed where its first point is written.
  EXPECT_EQ(raw.source.tetPosition, (std::vector<int64_t>{lineOf(text, "0 1 2 3 0"), lineOf(text, "1 2 3 4")}));
  EXPECT_EQ(raw.source.tetFileId, (std::vector<int64_t>{0, 2}));
  EXPECT_EQ(raw.report.skippedCells, 1);

  expectErrorAt(errorOf(replaced(text, "0 4 7 11", "0 4 3 11")), "bad.vtk", lineOf(text, "0 4 7 11"), "cell offset 3");
  expectErrorAt(errorOf(replaced(text, "0 4 7 11", "0 4 7 10")), "bad.vtk", lineOf(text, "0 4 7 11"),
                "last cell offset");
  const std::string bad = replaced(text, "1 2 3 4\n", "1 2 3 6\n");
  expectErrorAt(errorOf(bad), "bad.vtk", lineOf(bad, "1 2 3 6"), "cell 2: point index 6 is out of range [0, 6)");
}

// Writes numbers big-endian, as BINARY legacy files hold them.
struct BigEndianWriter {
  std::string bytes;
  template <class T>
  void put(T v) {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    if (hostIsLittleEndian()) std::reverse(raw, raw + sizeof(T));
    bytes.append(raw, sizeof(T));
  }
};

// Two tets and a triangle over 5 points, BINARY; `cellOffsets` receives the byte offset of each
// cell (of its point count in the classic layout, of its first point in the 5.1 layout).
std::string binarySample(bool vtk51, std::vector<int64_t>& cellOffsets) {
  BigEndianWriter w;
  w.bytes = "# vtk DataFile Version 5.1\nbinary\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 float\n";
  for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.25f, -3.5f, 1e-3f}) w.put(x);
  const std::vector<std::vector<int>> cells = {{0, 1, 2, 3}, {4, 2, 1}, {1, 2, 3, 4}};
  cellOffsets.clear();
  if (vtk51) {
    w.bytes += "\nCELLS 4 11\nOFFSETS vtktypeint64\n";
    for (int64_t o : {0, 4, 7, 11}) w.put(o);
    w.bytes += "\nCONNECTIVITY vtktypeint32\n";  // meshio's name for 32-bit connectivity
    for (const auto& cell : cells) {
      cellOffsets.push_back(static_cast<int64_t>(w.bytes.size()));
      for (int v : cell) w.put(static_cast<int32_t>(v));
    }
  } else {
    w.bytes += "\nCELLS 3 14\n";
    for (const auto& cell : cells) {
      cellOffsets.push_back(static_cast<int64_t>(w.bytes.size()));
      w.put(static_cast<int32_t>(cell.size()));
      for (int v : cell) w.put(static_cast<int32_t>(v));
    }
  }
  w.bytes += "\nCELL_TYPES 3\n";
  for (int32_t t : {10, 5, 10}) w.put(t);
  w.bytes += "\nCELL_DATA 3\nSCALARS pressure double\nLOOKUP_TABLE default\n";
  for (double p : {1.0, 2.0, 3.0}) w.put(p);
  w.bytes += "\nSCALARS gmsh:physical short\n";  // no LOOKUP_TABLE line: VTK accepts that
  for (int16_t r : {-4, 5, 600}) w.put(r);
  w.bytes += "\nPOINT_DATA 5\nVECTORS u float\n";
  for (int i = 0; i < 15; ++i) w.put(static_cast<float>(i));
  w.bytes += "\n";
  return w.bytes;
}

TEST(VtkLegacyRead, BinaryBigEndianClassicAnd51Layouts) {
  for (bool vtk51 : {false, true}) {
    SCOPED_TRACE(vtk51 ? "VTK 5.1 layout" : "classic layout");
    std::vector<int64_t> cellOffsets;
    const std::string bytes = binarySample(vtk51, cellOffsets);
    const RawMesh raw = parseVtkLegacy(bytes, "binary.vtk");
    ASSERT_EQ(raw.mesh.vertexCount(), 5);
    EXPECT_EQ(raw.mesh.vertices[4], Eigen::Vector3d(0.25, -3.5, static_cast<double>(1e-3f)));
    EXPECT_EQ(raw.mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 2, 3, 4}}));
    EXPECT_EQ(raw.mesh.tetRegion, (std::vector<int>{-4, 600}));
    EXPECT_EQ(raw.source.positionKind, SourcePositionKind::ByteOffset);
    EXPECT_EQ(raw.source.tetPosition, (std::vector<int64_t>{cellOffsets[0], cellOffsets[2]}));
    EXPECT_EQ(raw.source.tetFileId, (std::vector<int64_t>{0, 2}));
    EXPECT_EQ(raw.report.skippedCells, 1);

    // The last point index of the last cell out of range: named by the cell's byte offset.
    std::string bad = bytes;
    const size_t indexSize = 4, lastIndex = static_cast<size_t>(cellOffsets[2]) + (vtk51 ? 3 : 4) * indexSize;
    bad[lastIndex + indexSize - 1] = 9;
    std::string message = meshErrorOf([&] { parseVtkLegacy(bad, "bad.vtk"); });
    EXPECT_NE(message.find("bad.vtk: byte " + std::to_string(cellOffsets[2]) + ": cell 2: point index 9"),
              std::string::npos) << message;

    // Cut inside the coordinates.
    const size_t pointsStart = bytes.find("float\n") + 6;
    message = meshErrorOf([&] { parseVtkLegacy(std::string_view(bytes).substr(0, pointsStart + 30), "cut.vtk"); });
    EXPECT_NE(message.find("cut.vtk: byte "), std::string::npos) << message;
    const size_t typesEnd = bytes.find("CELL_TYPES 3\n") + 13 + 3 * 4;  // every shorter prefix is incomplete
    for (size_t cut = 0; cut < typesEnd; ++cut)
      EXPECT_NE(meshErrorOf([&] { parseVtkLegacy(std::string_view(bytes).substr(0, cut), "cut.vtk"); }), "")
          << "cut after " << cut << " bytes";

    // A NaN coordinate (the y of point 2), named by its byte offset.
    bad = bytes;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    BigEndianWriter nanBytes;
    nanBytes.put(nan);
    bad.replace(pointsStart + 7 * 4, 4, nanBytes.bytes);
    message = meshErrorOf([&] { parseVtkLegacy(bad, "nan.vtk"); });
    EXPECT_NE(message.find("nan.vtk: byte " + std::to_string(pointsStart + 28) + ": point 2"), std::string::npos)
        << message;
  }
}

TEST(VtkLegacyRead, SharedMfemBeam) {
  QUIVER_REQUIRE_SHARED_MESH(path, "mfem_beam-tet.vtk");
  const std::string text = readFileBytes(path);
  const RawMesh raw = parseVtkLegacy(text, path);
  const TetMesh& mesh = raw.mesh;
  EXPECT_EQ(mesh.vertexCount(), 36);
  ASSERT_EQ(mesh.tetCount(), 48);
  EXPECT_EQ(raw.report.skippedCells, 0);
  EXPECT_TRUE(raw.report.warnings.empty());
  // The box [0,8]x[0,1]x[0,1]: volume 8; its "material" array splits it at x = 4.
  double volume = 0;
  for (int t = 0; t < mesh.tetCount(); ++t) {
    volume += std::abs(signedVolume6(mesh, t)) / 6;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int v : mesh.tets[t]) centroid += mesh.vertices[v] / 4;
    EXPECT_EQ(mesh.tetRegion[t], centroid.x() < 4 ? 1 : 2) << "tet " << t;
  }
  EXPECT_NEAR(volume, 8.0, 1e-12);
  EXPECT_EQ(boundingBox(mesh)[0], Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(boundingBox(mesh)[1], Eigen::Vector3d(8, 1, 1));
  const int firstCell = lineOf(text, "CELLS 48 240") + 1;
  for (int t = 0; t < mesh.tetCount(); ++t) EXPECT_EQ(raw.source.tetPosition[t], firstCell + t);
}

TEST(VtkLegacyRead, SharedSofaMixedCells) {
  QUIVER_REQUIRE_SHARED_MESH(path, "sofa_SOFA_volume_mixedcells.vtk");
  const RawMesh raw = parseVtkLegacy(readFileBytes(path), path);
  EXPECT_EQ(raw.mesh.vertexCount(), 959);
  ASSERT_EQ(raw.mesh.tetCount(), 2564);
  EXPECT_EQ(raw.report.skippedCells, 4451 + 6057);
  ASSERT_EQ(raw.report.warnings.size(), 1u);
  for (const std::string& part : {path, std::string("4451 VTK_LINE"), std::string("6057 VTK_TRIANGLE")})
    EXPECT_NE(raw.report.warnings[0].find(part), std::string::npos) << raw.report.warnings[0];
  for (int t = 0; t < raw.mesh.tetCount(); ++t) EXPECT_GT(signedVolume6(raw.mesh, t), 0) << "tet " << t;
}

TEST(VtkLegacyWrite, RoundTripIsBitExact) {
  const TetMesh mesh = test::jitteredBox(7);
  std::mt19937 random(3);
  std::normal_distribution<double> normal;
  PointField displacement{"displacement", {}};
  for (int v = 0; v < mesh.vertexCount(); ++v)
    displacement.values.emplace_back(normal(random), normal(random) * 1e-9, normal(random) * 1e9);
  const std::string text = formatVtkLegacy(mesh, {displacement});
  test::expectSameMesh(mesh, parseVtkLegacy(text, "round.vtk").mesh);

  // The displacement, read back here with std::from_chars.
  const std::string header = "VECTORS displacement double\n";
  ASSERT_NE(text.find(header), std::string::npos);
  const char* p = text.data() + text.find(header) + header.size();
  for (const Eigen::Vector3d& u : displacement.values)
    for (int k = 0; k < 3; ++k) {
      double read = 0;
      const auto [end, ec] = std::from_chars(p, text.data() + text.size(), read);
      ASSERT_EQ(ec, std::errc());
      EXPECT_EQ(std::memcmp(&read, &u[k], sizeof read), 0) << read << " != " << u[k];
      p = end + 1;
    }

  TetMesh noRegions = mesh;
  noRegions.tetRegion.clear();
  EXPECT_EQ(parseVtkLegacy(formatVtkLegacy(noRegions), "plain.vtk").mesh.tetRegion,
            std::vector<int>(mesh.tetCount(), 0));
  EXPECT_THROW(formatVtkLegacy(mesh, {{"two words", displacement.values}}), MeshError);
  EXPECT_THROW(formatVtkLegacy(mesh, {{"short", {Eigen::Vector3d::Zero()}}}), MeshError);
}

TEST(VtkLegacyBadInput, PointIndexOutOfRange) {
  std::string text = replaced(kSample, "4 0 1 7 5", "4 0 1 7 10");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "4 0 1 7 10"), "cell 2: point index 10 is out of range [0, 10)");
  text = replaced(kSample, "4 0 1 3 7", "4 0 -1 3 7");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "4 0 -1 3 7"), "cell 0: point index -1");
}

TEST(VtkLegacyBadInput, NonNumericAndNonFinite) {
  std::string text = replaced(kMinimal, "0 1 0 0 0 1", "0 1 0 0 abc 1");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "abc"), "'abc'");
  text = replaced(kMinimal, "4 0 1 2 3", "4 0 1 two 3");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "two"), "'two'");
  text = replaced(kMinimal, "0 0 0 1 0 0", "0 0 0 1 nan 0");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "nan"), "point 1: coordinate is not finite");
  text = replaced(kMinimal, "0 0 1\n", "0 0 inf\n");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "inf"), "point 3: coordinate is not finite");
}

TEST(VtkLegacyBadInput, HugeCountsFailFast) {
  std::string text = replaced(kMinimal, "POINTS 4 double", "POINTS 999999999999 double");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "POINTS"), "999999999999 cannot fit");
  text = replaced(kMinimal, "CELLS 1 5", "CELLS 1 99999999999");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "CELLS"), "99999999999 cannot fit");
  text = kMinimal + "CELL_DATA 1\nFIELD f 1\nregion 1 88888888888 int\n";
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "region"), "88888888888");
}

TEST(VtkLegacyBadInput, TruncatedAnywhere) {
  test::expectEveryCutFails(kMinimal, "cut.vtk", [](std::string_view text) { parseVtkLegacy(text, "cut.vtk"); });
}

TEST(VtkLegacyBadInput, InconsistentOrUnsupported) {
  EXPECT_EQ(errorOf(replaced(kMinimal, "CELL_TYPES 1\n10", "CELL_TYPES 2\n10 10")),
            "bad.vtk: CELL_TYPES lists 2 cells, CELLS has 1");
  std::string text = replaced(kMinimal, "CELLS 1 5\n4 0 1 2 3", "CELLS 2 5\n4 0 1 2 3");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "4 0 1 2 3"), "holds 1 cells, CELLS declares 2");
  text = replaced(kMinimal, "CELL_TYPES 1\n10", "CELL_TYPES 1\n12");
  EXPECT_EQ(parseVtkLegacy(text, "hex.vtk").mesh.tetCount(), 0);  // a 4-point "hexahedron" is skipped, not read
  text = replaced(kMinimal, "CELLS 1 5\n4 0 1 2 3", "CELLS 1 4\n3 0 1 2");
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "3 0 1 2"), "VTK_TETRA cell has 3 points");
  expectErrorAt(errorOf(replaced(kMinimal, "UNSTRUCTURED_GRID", "POLYDATA")), "bad.vtk", 4,
                "only DATASET UNSTRUCTURED_GRID");
  expectErrorAt(errorOf(replaced(kMinimal, "ASCII", "TEXT")), "bad.vtk", 3, "expected ASCII or BINARY");
  expectErrorAt(errorOf(replaced(kMinimal, "# vtk", "# VTK")), "bad.vtk", 1, "not a VTK legacy file");
  text = kMinimal + "SCALARS s float\n1\n";
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "SCALARS"), "outside POINT_DATA and CELL_DATA");
  text = kMinimal + "CELL_DATA 1\nSCALARS region int\nLOOKUP_TABLE default\n5 66\n";
  expectErrorAt(errorOf(text), "bad.vtk", lineOf(text, "5 66"), "unknown keyword '66'");
}

} // namespace
} // namespace quiver
