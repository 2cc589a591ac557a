#pragma once
// Checks shared by the tests of our surface readers (own_readers.h).
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/mesh_error.h"
#include "formats/mesh/read_surface.h"

namespace quiver::test {

// The vertices and triangles readSurfaceFile() draws for `path` equal those of Assimp's own
// importer, positions to a float ulp (Assimp's fast_atoreal is not correctly rounded: Wuson.ply's
// "1.515251" comes out one ulp from the nearest float, which ours gives). Where Assimp's importer
// refuses the file, ours must too; returns whether the two were compared.
inline bool expectReadsAsAssimpsOwnImporter(const std::string& path) {
  Assimp::Importer theirs;
  const aiScene* scene = theirs.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure);
  if (!scene) {
    EXPECT_THROW(readSurfaceFile(path), MeshError) << path << ": Assimp's importer says " << theirs.GetErrorString();
    return false;
  }
  const SurfaceMesh ours = readSurfaceFile(path);
  std::vector<float> positions;
  std::vector<uint32_t> triangles;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const uint32_t first = static_cast<uint32_t>(positions.size() / 3);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      positions.insert(positions.end(), {mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z});
    for (unsigned f = 0; f < mesh->mNumFaces; ++f)
      for (unsigned k = 0; mesh->mFaces[f].mNumIndices == 3 && k < 3; ++k) triangles.push_back(first + mesh->mFaces[f].mIndices[k]);
  }
  EXPECT_EQ(ours.render.positions.size(), positions.size()) << path;
  EXPECT_EQ(ours.render.triangles.size(), triangles.size()) << path;
  if (ours.render.positions.size() != positions.size() || ours.render.triangles.size() != triangles.size()) return true;
  size_t p = 0, t = 0;
  while (p < positions.size() && std::fabs(ours.render.positions[p] - positions[p]) <= 1.2e-7 * std::fabs(positions[p])) ++p;
  while (t < triangles.size() && ours.render.triangles[t] == triangles[t]) ++t;
  EXPECT_EQ(p, positions.size()) << path << ": the first position that differs, " << ours.render.positions[p] << " against "
                                 << positions[p];
  EXPECT_EQ(t, triangles.size()) << path << ": the first triangle index that differs";
  return true;
}

// `text` with its first `from` replaced by `to`.
inline std::string edited(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

// readSurfaceMemory() refuses `bytes` in `format`: the message starts with `name` and says
// `expected`.
inline void expectSurfaceRefused(const std::string& bytes, const char* format, const std::string& name,
                                 const std::string& expected) {
  try {
    readSurfaceMemory(bytes.data(), bytes.size(), format, name);
    ADD_FAILURE() << "read: " << expected;
  } catch (const MeshError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(name, 0), 0u) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  }
}

} // namespace quiver::test
