#include "formats/mesh/read_surface.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <strings.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "common/mesh_error.h"
#include "common/surface.h"
#include "formats/mesh/own_readers.h"
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

// Points and lines are dropped by the importer; what remains is triangles, checked.
constexpr unsigned kSteps = aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType |
                            aiProcess_GenSmoothNormals | aiProcess_ValidateDataStructure;

void configure(Assimp::Importer& importer, const std::string& name) {
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  useOwnReaders(importer, name);
}

// Assimp triangulates a polygon in time quadratic in its corners (a 16 000-gon took 3.4 s, so a
// 250 000-gon would take about 15 minutes): polygons past kMaxCorners are refused before it does.
// The import itself validates the scene (Assimp does that before anything else reads it: indices
// out of range crashed its scene preprocessing), then the polygons are counted, then kSteps run.
constexpr unsigned kMaxCorners = 4096;
constexpr unsigned kImport = aiProcess_ValidateDataStructure;

const aiScene* postProcess(Assimp::Importer& importer, const aiScene* imported, const std::string& path) {
  if (!imported) return nullptr;
  for (unsigned m = 0; m < imported->mNumMeshes; ++m) {
    const aiMesh* mesh = imported->mMeshes[m];
    for (unsigned f = 0; mesh && mesh->mFaces && f < mesh->mNumFaces; ++f)
      if (mesh->mFaces[f].mNumIndices > kMaxCorners)
        throw MeshError(path + ": mesh " + std::to_string(m) + ", face " + std::to_string(f) + " has " +
                        std::to_string(mesh->mFaces[f].mNumIndices) + " corners, more than the " + std::to_string(kMaxCorners) +
                        " read here (triangulate it before export)");
  }
  return importer.ApplyPostProcessing(kSteps);
}

// The file behind a scene: its name, and where an OBJ's text can be read again (bytes in memory,
// or null: the file at `path`).
struct Source {
  const std::string& path;
  bool obj;
  const void* data = nullptr;
  size_t size = 0;
};

// "PATH:LINE: vertex N: ..." for the first "v" record of an OBJ with a coordinate that is not
// finite, or empty: Assimp numbers its faces' corners, which name no line of the file.
std::string nonFiniteObjVertex(const Source& source) {
  std::ifstream file;
  std::istringstream bytes;
  if (source.data)
    bytes.str(std::string(static_cast<const char*>(source.data), source.size));
  else
    file.open(source.path, std::ios::binary);
  std::istream& in = source.data ? static_cast<std::istream&>(bytes) : file;
  std::string line, tag, token;
  for (long number = 1, vertex = 0; std::getline(in, line); ++number) {
    std::istringstream fields(line);
    if (!(fields >> tag) || tag != "v") continue;
    ++vertex;
    for (int c = 0; c < 3 && fields >> token; ++c)
      if (!std::isfinite(std::strtod(token.c_str(), nullptr)))
        return source.path + ":" + std::to_string(number) + ": vertex " + std::to_string(vertex) + ": coordinate '" +
               token + "' is not finite";
  }
  return {};
}

// Assimp holds coordinates in single precision: far from the origin for its size, a surface is
// moved by their rounding (1e6 m away, a 0.2 m box lost 12% of its volume, silently). Refused
// where the rounding reaches a thousandth of the surface's size.
void checkSinglePrecision(const std::vector<double>& positions, const std::string& path) {
  double largest = 0, low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < positions.size(); ++i) {
    largest = std::max(largest, std::fabs(positions[i]));
    low[i % 3] = std::min(low[i % 3], positions[i]), high[i % 3] = std::max(high[i % 3], positions[i]);
  }
  const double size = std::hypot(high[0] - low[0], high[1] - low[1], high[2] - low[2]);
  const double rounding = largest > 0 ? std::ldexp(1.0, std::ilogb(largest) - 24) : 0.0;  // half a float's spacing there
  if (size > 0 && rounding > 1e-3 * size) {
    char text[320];
    std::snprintf(text, sizeof text,
                  ": coordinates up to %g for a surface %g across: read in single precision (Assimp), they are "
                  "rounded by up to %g, %.2g%% of its size; move it near the origin first",
                  largest, size, rounding, 100 * rounding / size);
    throw MeshError(path + text);
  }
}

SurfaceMesh fromScene(const aiScene* scene, const Assimp::Importer& importer, const Source& source) {
  const std::string& path = source.path;
  if (!scene || !scene->mRootNode) {
    const std::string error = importer.GetErrorString();  // our readers' (own_readers.h) already name the file
    throw MeshError(error.rfind(path + ":", 0) == 0 ? error : path + ": cannot read: " + error);
  }
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
      if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2])) {
        if (const std::string where = source.obj ? nonFiniteObjVertex(source) : ""; !where.empty()) throw MeshError(where);
        throw MeshError(path + ": mesh " + std::to_string(m) + ", vertex " + std::to_string(v) + ": coordinate is not finite");
      }
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
  checkSinglePrecision(s.positions, path);
  return s;
}

} // namespace

bool isTetMeshPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".vtu" || ext == ".vtk" || ext == ".msh" || ext == ".mesh" || ext == ".veg" || ext == ".node" ||
         ext == ".ele";
}

SurfaceMesh readSurfaceFile(const std::string& path) {
  openForReading(path);  // Assimp says no more than that it found no reader
  if (std::filesystem::path(path).extension() == ".qvr")
    throw MeshError(path + ": a baked model (.qvr), not a mesh: bake the mesh it was baked from");
  if (isTetMeshPath(path)) return tetBoundary(path);
  Assimp::Importer importer;
  configure(importer, path);
  return fromScene(postProcess(importer, importer.ReadFile(path, kImport), path), importer, {path, lowerExtension(path) == ".obj"});
}

SurfaceMesh readSurfaceMemory(const void* data, size_t size, const std::string& extension, const std::string& name) {
  Assimp::Importer importer;
  configure(importer, name);
  return fromScene(postProcess(importer, importer.ReadFileFromMemory(data, size, kImport, extension.c_str()), name), importer,
                   {name, strcasecmp(extension.c_str(), "obj") == 0, data, size});
}

} // namespace quiver
