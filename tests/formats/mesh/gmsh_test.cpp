// Gmsh reader/writer: the shared meshes, hand-built ASCII and binary files of both versions,
// and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <algorithm>
#include <limits>
#include <set>

#include "common/mesh_checks.h"
#include "common/mesh_error.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/write_mesh.h"
#include "tests/support/test_support.h"

using namespace quiver;

namespace {

// The same two tets (regions 7 and 8) plus one triangle in every encoding below.
const double kNodes[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
const int kTets[2][4] = {{1, 2, 3, 4}, {2, 3, 4, 5}};

const char* kAscii22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
3 7 "left"
$EndPhysicalNames
$Nodes
5
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 1 1
$EndNodes
$Elements
3
1 2 2 99 1 1 2 3
2 4 2 7 1 1 2 3 4
3 4 2 8 2 2 3 4 5
$EndElements
)";

const char* kAscii41 = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 0 1 2
1 0 0 0 1 1 0 1 99 0
1 0 0 0 1 1 1 1 7 0
2 0 0 0 1 1 1 1 8 0
$EndEntities
$Nodes
1 5 1 5
3 1 0 5
1
2
3
4
5
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
$EndNodes
$Elements
3 3 1 3
2 1 2 1
1 1 2 3
3 1 4 1
2 1 2 3 4
3 2 4 1
3 2 3 4 5
$EndElements
)";

// Little builder for binary test files; `swap` writes the other byte order.
struct Bytes {
  std::string s;
  bool swap = false;
  Bytes& text(const std::string& t) {
    s += t;
    return *this;
  }
  template <class T>
  Bytes& put(T v) {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    if (swap) std::reverse(raw, raw + sizeof(T));
    s.append(raw, sizeof(T));
    return *this;
  }
};

std::string binary22(bool swap) {
  Bytes b;
  b.swap = swap;
  b.text("$MeshFormat\n2.2 1 8\n").put<int32_t>(1).text("\n$EndMeshFormat\n$Nodes\n5\n");
  for (int i = 0; i < 5; ++i) {
    b.put<int32_t>(i + 1);
    for (double x : kNodes[i]) b.put(x);
  }
  b.text("\n$EndNodes\n$Elements\n3\n");
  b.put<int32_t>(2).put<int32_t>(1).put<int32_t>(2);  // one triangle, 2 tags
  b.put<int32_t>(1).put<int32_t>(99).put<int32_t>(1).put<int32_t>(1).put<int32_t>(2).put<int32_t>(3);
  b.put<int32_t>(4).put<int32_t>(2).put<int32_t>(2);  // two tets, 2 tags
  for (int e = 0; e < 2; ++e) {
    b.put<int32_t>(e + 2).put<int32_t>(7 + e).put<int32_t>(1);
    for (int v : kTets[e]) b.put<int32_t>(v);
  }
  b.text("\n$EndElements\n");
  return b.s;
}

std::string binary41() {
  Bytes b;
  b.text("$MeshFormat\n4.1 1 8\n").put<int32_t>(1).text("\n$EndMeshFormat\n$Entities\n");
  b.put<uint64_t>(0).put<uint64_t>(0).put<uint64_t>(1).put<uint64_t>(2);
  auto entity = [&](int tag, int physical, bool bounding) {
    b.put<int32_t>(tag);
    for (int k = 0; k < 6; ++k) b.put<double>(k < 3 ? 0.0 : 1.0);
    b.put<uint64_t>(1).put<int32_t>(physical);
    if (bounding) b.put<uint64_t>(0);
  };
  entity(1, 99, true);
  entity(1, 7, true);
  entity(2, 8, true);
  b.text("\n$EndEntities\n$Nodes\n");
  b.put<uint64_t>(1).put<uint64_t>(5).put<uint64_t>(1).put<uint64_t>(5);
  b.put<int32_t>(3).put<int32_t>(1).put<int32_t>(0).put<uint64_t>(5);
  for (int i = 0; i < 5; ++i) b.put<uint64_t>(i + 1);
  for (const auto& x : kNodes)
    for (double c : x) b.put(c);
  b.text("\n$EndNodes\n$Elements\n");
  b.put<uint64_t>(3).put<uint64_t>(3).put<uint64_t>(1).put<uint64_t>(3);
  b.put<int32_t>(2).put<int32_t>(1).put<int32_t>(2).put<uint64_t>(1);
  b.put<uint64_t>(1).put<uint64_t>(1).put<uint64_t>(2).put<uint64_t>(3);
  for (int e = 0; e < 2; ++e) {
    b.put<int32_t>(3).put<int32_t>(e + 1).put<int32_t>(4).put<uint64_t>(1);
    b.put<uint64_t>(e + 2);
    for (int v : kTets[e]) b.put<uint64_t>(v);
  }
  b.text("\n$EndElements\n");
  return b.s;
}

void expectSmallMesh(const RawMesh& r) {
  ASSERT_EQ(r.mesh.vertexCount(), 5);
  ASSERT_EQ(r.mesh.tetCount(), 2);
  for (int i = 0; i < 5; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(r.mesh.vertices[i][k], kNodes[i][k]);
  for (int e = 0; e < 2; ++e) {
    for (int k = 0; k < 4; ++k) EXPECT_EQ(r.mesh.tets[e][k], kTets[e][k] - 1);
    EXPECT_EQ(r.mesh.tetRegion[e], 7 + e);
  }
  EXPECT_EQ(r.report.skippedCells, 1);
}

std::string errorOf(const std::string& bytes, const std::string& name = "t.msh") {
  try {
    parseGmsh(bytes, name);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(GmshReader, AsciiAndBinaryOfBothVersionsAgree) {
  expectSmallMesh(parseGmsh(kAscii22, "a22.msh"));
  expectSmallMesh(parseGmsh(kAscii41, "a41.msh"));
  expectSmallMesh(parseGmsh(binary22(false), "b22.msh"));
  expectSmallMesh(parseGmsh(binary22(true), "b22swapped.msh"));
  expectSmallMesh(parseGmsh(binary41(), "b41.msh"));
}

TEST(GmshReader, RecordsWhereEachTetCameFrom) {
  RawMesh r = parseGmsh(kAscii22, "a22.msh");
  EXPECT_EQ(r.source.describeTet(1), "a22.msh:20: element 3");
  RawMesh b = parseGmsh(binary22(false), "b.msh");
  EXPECT_EQ(b.source.positionKind, SourcePositionKind::ByteOffset);
}

TEST(GmshReader, Tet10KeepsCorners) {
  std::string s = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
10
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 .5 0 0
6 .5 .5 0
7 0 .5 0
8 0 0 .5
9 0 .5 .5
10 .5 0 .5
$EndNodes
$Elements
1
1 11 0 1 2 3 4 5 6 7 8 9 10
$EndElements
)";
  RawMesh r = parseGmsh(s, "q.msh");
  ASSERT_EQ(r.mesh.tetCount(), 1);
  EXPECT_EQ(r.mesh.tets[0], (Tet{0, 1, 2, 3}));
  ASSERT_EQ(r.report.warnings.size(), 1u);
  EXPECT_NE(r.report.warnings[0].find("10-node"), std::string::npos);
}

TEST(GmshReader, BadInputNamesFileAndLine) {
  auto replaced = [](const std::string& from, const std::string& to) {
    std::string t = kAscii22;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  EXPECT_NE(errorOf(replaced("3 4 2 8 2 2 3 4 5", "3 4 2 8 2 2 3 4 6"), "x.msh")
                .find("x.msh:20: element 3 refers to node 6"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced("4 0 0 1", "4 0 zero 1")).find("t.msh:13: expected a number for node coordinate"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced("4 0 0 1", "4 0 nan 1")).find("t.msh:13: node coordinate is not finite"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced("2.2 0 8", "3.0 0 8")).find("unsupported Gmsh format version '3.0'"), std::string::npos);
  EXPECT_NE(errorOf(replaced("$Nodes\n5", "$Nodes\n99999999999")).find("cannot fit"), std::string::npos);
  EXPECT_NE(errorOf(replaced("5 1 1 1", "4 1 1 1")).find("node tag 4 appears twice"), std::string::npos);
  EXPECT_NE(errorOf(replaced("3 4 2 8", "3 77 2 8")).find("element type 77"), std::string::npos);
}

TEST(GmshReader, EveryTruncationIsAClearErrorNeverACrash) {
  for (const std::string& full : {std::string(kAscii41), binary22(false), binary41()})
    for (size_t cut = 0; cut + 1 < full.size(); ++cut) {
      std::string part = full.substr(0, cut);
      std::string msg = errorOf(part, "cut.msh");
      // A cut inside the trailing "$EndElements\n" keeps all data; everything else must fail.
      if (cut < full.rfind("$EndElements")) {
        EXPECT_EQ(msg.rfind("cut.msh", 0), 0u) << "cut at " << cut << ": '" << msg << "'";
      }
    }
}

TEST(GmshReader, BinaryCountThatCannotFitFailsFast) {
  std::string b = binary41();
  const size_t nodes = b.find("$Nodes\n") + 7;
  const uint64_t huge = uint64_t(1) << 60;
  std::memcpy(&b[nodes + 8], &huge, 8);
  std::string msg = errorOf(b, "huge.msh");
  EXPECT_NE(msg.find("huge.msh: byte " + std::to_string(nodes + 8) + ": node count"), std::string::npos) << msg;
}

TEST(GmshWriter, RoundTripIsExact) {
  RawMesh r = parseGmsh(kAscii41, "a.msh");
  r.mesh.vertices[4] = Eigen::Vector3d(1.0 / 3.0, std::nextafter(1.0, 2.0), -1e-300);
  RawMesh back = parseGmsh(formatGmsh(r.mesh), "back.msh");
  EXPECT_EQ(back.mesh.vertices, r.mesh.vertices);
  EXPECT_EQ(back.mesh.tets, r.mesh.tets);
  EXPECT_EQ(back.mesh.tetRegion, r.mesh.tetRegion);
}

TEST(GmshSharedMeshes, PolyfemBarSeriesCounts) {
  const std::pair<const char*, std::pair<int, int>> series[] = {{"polyfem_bar-186.msh", {86, 186}},
                                                                {"polyfem_bar-651.msh", {292, 651}},
                                                                {"polyfem_bar-2523.msh", {886, 2523}},
                                                                {"polyfem_bar-14114.msh", {3842, 14114}}};
  for (const auto& [name, counts] : series) {
    QUIVER_REQUIRE_SHARED_MESH(path, name);
    CheckedMesh m = loadMesh(path);
    EXPECT_EQ(m.mesh.vertexCount(), counts.first) << name;
    EXPECT_EQ(m.mesh.tetCount(), counts.second) << name;
    EXPECT_NEAR(totalVolume(m.mesh), 10 * 0.5 * 1, 1e-9) << name;  // the 10 x 0.5 x 1 bar
  }
}

TEST(GmshSharedMeshes, CubesV22AndV41LoadIdentically) {
  QUIVER_REQUIRE_SHARED_MESH(v22, "polyfem_cubes_v22.msh");
  QUIVER_REQUIRE_SHARED_MESH(v41, "polyfem_cubes_v41.msh");
  CheckedMesh a = loadMesh(v22), b = loadMesh(v41);
  EXPECT_EQ(a.mesh.vertexCount(), 7714);
  EXPECT_EQ(a.mesh.tetCount(), 32981);
  EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
  EXPECT_EQ(a.mesh.tets, b.mesh.tets);
  EXPECT_EQ(a.mesh.tetRegion, b.mesh.tetRegion);
  std::set<int> regions(a.mesh.tetRegion.begin(), a.mesh.tetRegion.end());
  EXPECT_EQ(regions, (std::set<int>{1, 2, 3}));
}

TEST(GmshSharedMeshes, InvertedSofaTetIsRefusedByLineAndElement) {
  QUIVER_REQUIRE_SHARED_MESH(path, "sofa_6_tetra_bad.msh");
  RawMesh raw = readMeshFile(path);
  EXPECT_EQ(raw.mesh.vertexCount(), 17);
  EXPECT_EQ(raw.mesh.tetCount(), 6);
  // Line 31 holds the only tet with negative volume (-4.5, worked out by hand from the file).
  try {
    checkMesh(raw);
    FAIL() << "inverted mesh accepted";
  } catch (const MeshError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find(path + ":31: element 44 is inverted: signed volume -4.5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("1 inverted tets in total; pass --fix-orientation"), std::string::npos) << msg;
  }
  MeshCheckOptions fix;
  fix.fixOrientation = true;
  CheckedMesh fixed = checkMesh(readMeshFile(path), fix);
  EXPECT_EQ(fixed.flippedTets, 1);
  for (int t = 0; t < fixed.mesh.tetCount(); ++t) EXPECT_GT(signedVolume6(fixed.mesh, t), 0);
}
