// Surfaces through Assimp (formats/mesh/read_surface.h): the fuzzer's seed cube in five formats
// reads as a closed unit cube (welded: 8 vertices, 12 triangles, volume 1); a textured glTF from
// Debian's assimp-testmodels keeps its split vertices, normals and UVs for drawing; what is not a
// surface is named.
#include <gtest/gtest.h>

#include <filesystem>

#include "common/mesh_error.h"
#include "common/surface_check.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/read_surface.h"
#include "tests/support/test_support.h"

namespace quiver {
namespace {

TEST(ReadSurface, TheSeedCubeReadsAlikeInEveryFormat) {
  const char* const formats[] = {"obj", "stl", "ply", "off", "gltf", "glb"};
  for (const char* name : {"cube.obj", "cube_ascii.stl", "cube_binary.stl", "cube.ply", "cube.off"}) {
    const std::string bytes = readFileBytes(test::asset(std::string("../fuzz/seeds/surface/") + name));
    ASSERT_FALSE(bytes.empty()) << name;
    const SurfaceMesh s = readSurfaceMemory(bytes.data() + 1, bytes.size() - 1, formats[bytes[0] % 6], name);
    EXPECT_EQ(s.positions.size(), 24u) << name;
    const CheckedSurface c = checkSurface(s.positions, s.triangles, name);
    EXPECT_EQ(c.triangles.size(), 12u) << name;
    EXPECT_NEAR(c.volume, 1, 1e-6) << name;
    EXPECT_EQ(s.render.triangles.size(), 36u) << name;
    EXPECT_EQ(s.render.normals.size(), s.render.positions.size()) << name;
  }
}

TEST(ReadSurface, ATexturedGltfKeepsItsVerticesNormalsAndUVsForDrawing) {
  const std::string path = "/usr/share/assimp/models/glTF2/BoxTextured-glTF/BoxTextured.gltf";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "Debian's assimp-testmodels is not installed: " << path;
  const SurfaceMesh s = readSurfaceFile(path);
  EXPECT_EQ(s.positions.size() / 3, 8u);            // welded: a box
  EXPECT_EQ(s.render.positions.size() / 3, 24u);     // drawn: four vertices a face
  EXPECT_EQ(s.render.uvs.size() / 2, 24u);
  EXPECT_EQ(s.render.triangles.size() / 3, 12u);
}

TEST(ReadSurface, WhatIsNotASurfaceIsNamed) {
  const std::string text = "this is not a mesh";
  try {
    readSurfaceMemory(text.data(), text.size(), "obj", "notes.obj");
    ADD_FAILURE() << "read";
  } catch (const MeshError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("notes.obj: ", 0), 0u) << e.what();
  }
  EXPECT_THROW(readSurfaceFile("/nonexistent/x.obj"), MeshError);
}

TEST(ReadSurface, HeaderCountsTheFileCannotHoldAreRefusedBeforeAssimpAllocatesThem) {
  // Found by fuzz.surface: Assimp's OFF importer allocated the 7.7e12 faces this header claims.
  const std::string off = "OFF\n4 7777777777776 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n";
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nend_header\n0\n";
  for (const auto& [bytes, format] : {std::pair{off, "off"}, std::pair{ply, "ply"}}) {
    try {
      readSurfaceMemory(bytes.data(), bytes.size(), format, std::string("bad.") + format);
      ADD_FAILURE() << format << " read";
    } catch (const MeshError& e) {
      EXPECT_NE(std::string(e.what()).find("more than its " + std::to_string(bytes.size()) + " bytes can hold"), std::string::npos)
          << e.what();
    }
  }
}

} // namespace
} // namespace quiver
