#include "formats/mesh/read_surface.h"

#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string_view>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "common/mesh_error.h"
#include "common/surface.h"
#include "formats/mesh/read_mesh.h"

namespace quiver {

namespace {

SurfaceMesh tetBoundary(const std::string& path) {
  const CheckedMesh checked = loadMesh(path);
  SurfaceMesh s;
  for (const Eigen::Vector3d& x : checked.mesh.vertices) s.positions.insert(s.positions.end(), {x[0], x[1], x[2]});
  for (const auto& t : boundaryTriangles(checked.mesh)) s.triangles.insert(s.triangles.end(), {t[0], t[1], t[2]});
  return s;
}

// Assimp's OFF and PLY importers allocate what their headers count before reading on: a few
// corrupt bytes ("OFF 8 611111111111") would ask for gigabytes. Counts a file of this size cannot
// hold are refused here first (an element takes at least one byte; an OFF vertex at least 6).
void checkHeaderCounts(std::string_view bytes, const std::string& extension, const std::string& name) {
  std::string ext = extension;
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const auto refuse = [&](const std::string& what) {
    throw MeshError(name + ": the header counts " + what + ", more than its " + std::to_string(bytes.size()) + " bytes can hold");
  };
  std::istringstream in(std::string(bytes.substr(0, 65536)));
  std::string word;
  if (ext == "off") {
    double vertices = 0, faces = 0;  // after OFF (or COFF, NOFF, ...); anything else the importer judges
    if (!(in >> word) || word.find("OFF") == std::string::npos || !(in >> vertices >> faces)) return;
    if (6 * vertices + faces > double(bytes.size()))
      refuse(std::to_string(static_cast<long long>(std::fmin(vertices, 9e18))) + " vertices and " +
             std::to_string(static_cast<long long>(std::fmin(faces, 9e18))) + " faces");
  } else if (ext == "ply") {
    double total = 0;
    for (std::string line; std::getline(in, line) && line.rfind("end_header", 0) != 0;) {
      std::istringstream fields(line);
      std::string keyword, element;
      double count = 0;
      if (fields >> keyword >> element >> count && keyword == "element" && count > 0) total += count;
    }
    if (total > double(bytes.size())) refuse(std::to_string(static_cast<long long>(std::fmin(total, 9e18))) + " elements");
  }
}

// Points and lines are dropped by the importer; what remains is triangles, checked.
constexpr unsigned kSteps = aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType |
                            aiProcess_GenSmoothNormals | aiProcess_ValidateDataStructure;

void configure(Assimp::Importer& importer) {
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
}

SurfaceMesh fromScene(const aiScene* scene, const Assimp::Importer& importer, const std::string& path) {
  if (!scene || !scene->mRootNode) throw MeshError(path + ": cannot read: " + importer.GetErrorString());
  SurfaceMesh s;
  std::map<std::array<double, 3>, int> welded;
  bool anyUVs = false;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) anyUVs = anyUVs || scene->mMeshes[m]->HasTextureCoords(0);
  SurfaceMesh::Render& render = s.render;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const uint32_t first = static_cast<uint32_t>(render.positions.size() / 3);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D &p = mesh->mVertices[v], n = mesh->HasNormals() ? mesh->mNormals[v] : aiVector3D(0, 0, 1);
      render.positions.insert(render.positions.end(), {p.x, p.y, p.z});
      render.normals.insert(render.normals.end(), {std::isfinite(n.x) ? n.x : 0, std::isfinite(n.y) ? n.y : 0, std::isfinite(n.z) ? n.z : 1});
      if (anyUVs) {
        const aiVector3D uv = mesh->HasTextureCoords(0) ? mesh->mTextureCoords[0][v] : aiVector3D(0, 0, 0);
        render.uvs.insert(render.uvs.end(), {std::isfinite(uv.x) ? uv.x : 0, std::isfinite(uv.y) ? uv.y : 0});
      }
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 3)
        for (int k = 0; k < 3; ++k) render.triangles.push_back(first + face.mIndices[k]);
    }
    std::vector<int> index(mesh->mNumVertices);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const std::array<double, 3> x{p.x, p.y, p.z};
      if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
        throw MeshError(path + ": mesh " + std::to_string(m) + ", vertex " + std::to_string(v) + ": coordinate is not finite");
      const auto [it, added] = welded.emplace(x, static_cast<int>(s.positions.size() / 3));
      if (added) s.positions.insert(s.positions.end(), x.begin(), x.end());
      index[v] = it->second;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      s.triangles.insert(s.triangles.end(), {index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]});
    }
  }
  if (s.triangles.empty()) throw MeshError(path + ": holds no triangle");
  return s;
}

} // namespace

bool isTetMeshPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".vtu" || ext == ".vtk" || ext == ".msh" || ext == ".mesh" || ext == ".veg" || ext == ".node" ||
         ext == ".ele";
}

SurfaceMesh readSurfaceFile(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw MeshError(path + ": cannot open: no such file");
  if (isTetMeshPath(path)) return tetBoundary(path);
  std::string extension = std::filesystem::path(path).extension().string();
  if (!extension.empty()) extension.erase(0, 1);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == "off" || extension == "ply") checkHeaderCounts(readFileBytes(path), extension, path);
  Assimp::Importer importer;
  configure(importer);
  return fromScene(importer.ReadFile(path, kSteps), importer, path);
}

SurfaceMesh readSurfaceMemory(const void* data, size_t size, const std::string& extension, const std::string& name) {
  checkHeaderCounts(std::string_view(static_cast<const char*>(data), size), extension, name);
  Assimp::Importer importer;
  configure(importer);
  return fromScene(importer.ReadFileFromMemory(data, size, kSteps, extension.c_str()), importer, name);
}

} // namespace quiver
