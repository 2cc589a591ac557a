// Vega .veg and .bou: the shared beam and bridge, materials/sets/regions, and bad input.
#include <gtest/gtest.h>

#include <fstream>

#include "common/mesh_checks.h"
#include "common/mesh_error.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/write_mesh.h"
#include "tests/support/test_support.h"

using namespace quiver;

namespace {

const char* kTwoMaterials = R"(# two tets, two materials
*VERTICES
5 3 0 0
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 1 1   # trailing comment

*ELEMENTS
TET
2 4 0
1 1 2 3 4
2 2 3 4 5

*MATERIAL soft
ENU, 1000, 1e5, 0.4
*MATERIAL hard
ENU, 2000, 1e8, 0.3

*SET second
2,

*REGION
allElements, soft
second, hard
)";

std::string errorOf(const std::string& text) {
  try {
    parseVega(text, "m.veg");
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

std::string replaced(const std::string& from, const std::string& to) {
  std::string t = kTwoMaterials;
  t.replace(t.find(from), from.size(), to);
  return t;
}

} // namespace

TEST(VegaReader, MaterialsSetsAndRegions) {
  RawMesh r = parseVega(kTwoMaterials, "m.veg");
  ASSERT_EQ(r.mesh.vertexCount(), 5);
  ASSERT_EQ(r.mesh.tetCount(), 2);
  EXPECT_EQ(r.mesh.tets[1], (Tet{1, 2, 3, 4}));
  ASSERT_EQ(r.mesh.materials.size(), 2u);
  EXPECT_EQ(r.mesh.materials[1].name, "hard");
  EXPECT_EQ(r.mesh.materials[1].density, 2000);
  EXPECT_EQ(r.mesh.materials[1].youngsModulus, 1e8);
  EXPECT_EQ(r.mesh.materials[1].poissonRatio, 0.3);
  EXPECT_EQ(r.mesh.tetMaterial, (std::vector<int>{0, 1}));  // the later region wins
  EXPECT_EQ(r.source.describeTet(1), "m.veg:14: element 2");
}

TEST(VegaReader, BadInput) {
  EXPECT_NE(errorOf(replaced("2 2 3 4 5", "2 2 3 4 6")).find("m.veg:14: element vertex 6 is out of range [1, 5]"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced("ENU, 2000, 1e8, 0.3", "ENU, 2000, 1e8, 0.7")).find("m.veg:19: material 'hard': Poisson"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced("ENU, 2000, 1e8", "ENU, 2000, x")).find("'x' is not a number"), std::string::npos);
  EXPECT_NE(errorOf(replaced("second, hard", "second, steel")).find("m.veg:26: region uses undefined material 'steel'"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced("2,\n", "3,\n")).find("set 'second': element 3 is out of range"), std::string::npos);
  EXPECT_NE(errorOf(replaced("5 3 0 0", "99999999 3 0 0")).find("cannot fit"), std::string::npos);
  EXPECT_NE(errorOf(replaced("TET\n", "CUBIC\n")).find("'CUBIC' is not supported"), std::string::npos);
  EXPECT_NE(errorOf(replaced("4 0 0 1", "4 0 inf 1")).find("m.veg:7: vertex coordinate is not finite"), std::string::npos);
  std::string full = kTwoMaterials;
  for (size_t cut = 0; cut <= full.find("2 2 3 4 5") + 8; ++cut) {  // every cut before the last element ends
    std::string msg = errorOf(full.substr(0, cut));
    EXPECT_EQ(msg.rfind("m.veg", 0), 0u) << "cut at " << cut << ": " << msg;
  }
}

TEST(VegaWriter, RoundTripKeepsMaterials) {
  RawMesh r = parseVega(kTwoMaterials, "m.veg");
  RawMesh back = parseVega(formatVega(r.mesh), "back.veg");
  EXPECT_EQ(back.mesh.vertices, r.mesh.vertices);
  EXPECT_EQ(back.mesh.tets, r.mesh.tets);
  EXPECT_EQ(back.mesh.tetMaterial, r.mesh.tetMaterial);
  ASSERT_EQ(back.mesh.materials.size(), 2u);
  EXPECT_EQ(back.mesh.materials[0].youngsModulus, 1e5);
}

// quiver-mesh convert warns of what the target format drops: what it says matches what a round
// trip through that format loses.
TEST(VegaWriter, WhatAFormatDropsIsSaid) {
  const RawMesh r = parseVega(kTwoMaterials, "m.veg");
  EXPECT_TRUE(droppedByFormat("x.veg", r.mesh).empty());
  const std::vector<std::string> vtu = droppedByFormat("x.vtu", r.mesh);
  ASSERT_EQ(vtu.size(), 1u);
  EXPECT_EQ(vtu[0].rfind("x.vtu cannot hold materials: the mesh's are dropped (soft, hard;", 0), 0u) << vtu[0];
  EXPECT_TRUE(parseVtu(formatVtu(r.mesh), "x.vtu").mesh.materials.empty());

  TetMesh regions = r.mesh;  // two regions and no material
  regions.materials.clear();
  regions.tetMaterial.clear();
  regions.tetRegion = {3, 7};
  const std::vector<std::string> veg = droppedByFormat("x.veg", regions);
  ASSERT_EQ(veg.size(), 1u);
  EXPECT_NE(veg[0].find("its 2 regions are merged into one"), std::string::npos) << veg[0];
  const std::vector<int> back = parseVega(formatVega(regions), "x.veg").mesh.tetRegion;
  EXPECT_TRUE(back.empty() || back[0] == back[1]);
  EXPECT_TRUE(droppedByFormat("x.msh", regions).empty());
  EXPECT_EQ(parseGmsh(formatGmsh(regions), "x.msh").mesh.tetRegion, (std::vector<int>{3, 7}));
}

TEST(BouReader, ParsesOneBasedListsAndRefusesBadNumbers) {
  EXPECT_EQ(parseBou("3,1,\n5 # end\n", "f.bou", 5), (std::vector<int>{2, 0, 4}));
  EXPECT_EQ(parseBou("1 2\n", "f.bou", 5), (std::vector<int>{0, 1}));
  try {
    parseBou("1,2,\n6,\n", "f.bou", 5);
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("f.bou:2: vertex 6 is out of range [1, 5]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parseBou("1,x\n", "f.bou", 5), MeshError);
  EXPECT_THROW(parseBou("0\n", "f.bou", 5), MeshError);
}

TEST(BouReader, AFileBecomesAOneBasedVertexListNamedByThePath) {
  const std::string path = test::tempDir("bou_file") + "/fixed.bou";
  std::ofstream(path) << "# fixed\n4, 2,\n9\n";
  const FileVertexList list = readBouFile(path);
  EXPECT_EQ(list.source, path);
  EXPECT_EQ(list.indices, (std::vector<int64_t>{3, 1, 8}));
  EXPECT_EQ(list.firstNumber, 1);
  std::ofstream(path) << "4,\nfour\n";
  EXPECT_NE(test::errorOf<MeshError>([&] { readBouFile(path); }).find(path + ":2: 'four' is not a vertex number"),
            std::string::npos);
  EXPECT_NE(test::errorOf<MeshError>([&] { readBouFile(path + ".missing"); }).find("cannot open"), std::string::npos);
}

TEST(VegaSharedMeshes, BeamAndBridge) {
  QUIVER_REQUIRE_SHARED_MESH(beam, "vega_beam3_tet.veg");
  CheckedMesh m = loadMesh(beam);
  EXPECT_EQ(m.mesh.vertexCount(), 208);
  EXPECT_EQ(m.mesh.tetCount(), 450);
  ASSERT_EQ(m.mesh.materials.size(), 1u);
  EXPECT_EQ(m.mesh.materials[0].density, 1000);
  EXPECT_EQ(m.mesh.materials[0].youngsModulus, 1e7);
  EXPECT_EQ(m.mesh.materials[0].poissonRatio, 0.45);
  EXPECT_NEAR(totalVolume(m.mesh), 0.12 * 1.0 * 0.04, 1e-12);
  std::vector<int> fixed = parseBou(readFileBytes(beam.substr(0, beam.size() - 4) + ".bou"), "beam.bou", 208);
  EXPECT_EQ(fixed.size(), 8u);
  for (int v : fixed) EXPECT_NEAR(m.mesh.vertices[v].y(), 1.0, 1e-12);  // the README: the y = 1 end

  QUIVER_REQUIRE_SHARED_MESH(bridge, "vega_simpleBridge_tet.veg");
  CheckedMesh b = loadMesh(bridge);
  EXPECT_EQ(b.mesh.vertexCount(), 4000);
  EXPECT_EQ(b.mesh.tetCount(), 12827);
  EXPECT_EQ(parseBou(readFileBytes(bridge.substr(0, bridge.size() - 4) + ".bou"), "bridge.bou", 4000).size(), 121u);
}
