// Surfaces through Assimp (formats/mesh/read_surface.h): the fuzzer's seed cube in five formats
// (PLY and OFF through our readers, own_readers.h)
// reads as a closed unit cube (welded: 8 vertices, 12 triangles, volume 1); a textured glTF from
// Debian's assimp-testmodels keeps its split vertices, normals and UVs for drawing; what is not a
// surface is named.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/mesh_error.h"
#include "common/surface_check.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/read_surface.h"
#include "tests/support/test_support.h"

namespace quiver {
namespace {

TEST(ReadSurface, TheSeedCubeReadsAlikeInEveryFormat) {
  const char* const formats[] = {"obj", "stl", "ply", "off", "gltf", "glb"};
  for (const char* name : {"cube.obj", "cube_ascii.stl", "cube_binary.stl", "cube.ply", "cube_binary.ply", "cube.off",
                           "cube_prefixed.off"}) {
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
  EXPECT_EQ(test::errorOf<MeshError>([] { readSurfaceFile("/nonexistent/x.obj"); }),
            "/nonexistent/x.obj: cannot open: No such file or directory");
  // A directory was once "no such file"; a baked model, Assimp's "no suitable reader".
  const std::string directory = std::filesystem::temp_directory_path().string();
  EXPECT_EQ(test::errorOf<MeshError>([&] { readSurfaceFile(directory); }), directory + ": cannot open: is a directory");
  const std::string model = test::asset("../fuzz/seeds/qvr/float64.qvr");
  EXPECT_NE(test::errorOf<MeshError>([&] { readSurfaceFile(model); }).find("a baked model (.qvr), not a mesh"),
            std::string::npos);
}

// Debian's concave_polygon.obj is one flat concave 64-gon, a sheet: with its holes closed it
// encloses a rounding error's volume. Compared with the product of its box's sides, zero for a
// flat box, that passed, and gmsh then ran for ever on it.
TEST(ReadSurface, AFlatPolygonWithItsHolesClosedEnclosesNoVolume) {
  const std::string path = "/usr/share/assimp/models/OBJ/concave_polygon.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "Debian's assimp-testmodels is not installed: " << path;
  const SurfaceMesh s = readSurfaceFile(path);
  SurfaceCheckOptions options;
  options.fillHoles = true;
  EXPECT_NE(test::errorOf<MeshError>([&] { checkSurface(s.positions, s.triangles, path, options); }).find("encloses no volume"),
            std::string::npos);
}

TEST(ReadSurface, ANonFiniteObjCoordinateIsNamedAtItsLine) {
  // Assimp numbers the vertices of its faces' corners, so its index named no line of the file.
  const std::string text = "# a tetrahedron\nv 0 0 0\nv 1 0 0\n\nv 0 nan 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n";
  EXPECT_EQ(test::errorOf<MeshError>([&] { readSurfaceMemory(text.data(), text.size(), "obj", "bad.obj"); }),
            "bad.obj:5: vertex 3: coordinate 'nan' is not finite");
  const std::string path = test::tempDir("ReadSurfaceNonFiniteObj") + "/bad.OBJ";
  std::string overflowing = text;
  overflowing.replace(overflowing.find("nan"), 3, "1e999");
  std::ofstream(path, std::ios::binary) << overflowing;
  EXPECT_EQ(test::errorOf<MeshError>([&] { readSurfaceFile(path); }), path + ":5: vertex 3: coordinate '1e999' is not finite");
}

// Assimp reads coordinates in single precision: a 0.2 m tetrahedron 1e6 m from the origin was
// rounded by up to 6 cm and baked 12% smaller, silently. 1e3 m away it reads as it is.
TEST(ReadSurface, CoordinatesSinglePrecisionRoundsTooFarAreRefused) {
  const auto tetrahedron = [](double offset) {
    std::string text;
    for (const char* corner : {"0 0 0", "0.2 0 0", "0 0.2 0", "0 0 0.2"}) {
      std::istringstream in(corner);
      double x, y, z;
      in >> x >> y >> z;
      text += "v " + std::to_string(x + offset) + " " + std::to_string(y + offset) + " " + std::to_string(z + offset) + "\n";
    }
    return text + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  };
  const std::string far = tetrahedron(1e6);
  const std::string error = test::errorOf<MeshError>([&] { readSurfaceMemory(far.data(), far.size(), "obj", "far.obj"); });
  EXPECT_EQ(error.rfind("far.obj: coordinates up to 1e+06 for a surface ", 0), 0u) << error;
  EXPECT_NE(error.find("read in single precision (Assimp), they are rounded by up to 0.03125, 9.6% of its size"), std::string::npos) << error;
  const std::string near = tetrahedron(1e3);
  const SurfaceMesh s = readSurfaceMemory(near.data(), near.size(), "obj", "near.obj");
  double low = INFINITY, high = -INFINITY;
  for (size_t i = 0; i < s.positions.size(); i += 3) low = std::min(low, s.positions[i]), high = std::max(high, s.positions[i]);
  EXPECT_NEAR(low, 1e3, 1e-4);
  EXPECT_NEAR(high - low, 0.2, 1e-4);
}

TEST(ReadSurface, PolygonsTooLargeToTriangulateAreRefusedInEveryFormat) {
  // Assimp's triangulation is quadratic in a polygon's corners: 5000 are refused before it runs.
  std::string obj, ply = "ply\nformat ascii 1.0\nelement vertex 5000\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list ushort int vertex_indices\nend_header\n";
  std::string face = "f", plyFace = "5000";
  for (int i = 0; i < 5000; ++i) {
    const std::string xyz = std::to_string(std::cos(i * 2e-3 * M_PI)) + " " + std::to_string(std::sin(i * 2e-3 * M_PI)) + " 0\n";
    obj += "v " + xyz, ply += xyz;
    face += " " + std::to_string(i + 1), plyFace += " " + std::to_string(i);
  }
  obj += face + "\n", ply += plyFace + "\n";
  for (const auto& [bytes, format] : {std::pair{obj, "obj"}, std::pair{ply, "ply"}}) {
    try {
      readSurfaceMemory(bytes.data(), bytes.size(), format, std::string("disc.") + format);
      ADD_FAILURE() << format << " read";
    } catch (const MeshError& e) {
      EXPECT_NE(std::string(e.what()).find("disc." + std::string(format) + ": mesh 0, face 0 has 5000 corners, more than the 4096"),
                std::string::npos) << e.what();
    }
  }
}

} // namespace
} // namespace quiver
