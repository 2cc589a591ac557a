#pragma once
// Writing tetrahedral meshes. format* functions return the file's bytes; writeMeshFile() writes
// atomically (temporary file, then rename), so a failed write never leaves a half-written file.
#include <string>
#include <utility>
#include <vector>

#include "common/tet_mesh.h"
#include "formats/mesh/read_mesh.h"

namespace quiver {

// Per-vertex 3-vector data written beside the mesh (e.g. "displacement" for ParaView).
struct PointField {
  std::string name;
  std::vector<Eigen::Vector3d> values; // one per vertex
};

enum class VtuEncoding { Ascii, AppendedRaw };

std::string formatVtu(const TetMesh& mesh, const std::vector<PointField>& fields = {},
                      VtuEncoding encoding = VtuEncoding::AppendedRaw);
// A triangle surface (a render mesh's frame) as .vtu: float32 points, per-point normals when given.
std::string formatTriangleVtu(const std::vector<float>& positions, const std::vector<unsigned>& triangles,
                              const std::vector<float>& normals = {});
std::string formatVtkLegacy(const TetMesh& mesh, const std::vector<PointField>& fields = {});  // ASCII
std::string formatGmsh(const TetMesh& mesh);   // Gmsh 4.1 ASCII; regions become physical volumes
std::string formatMedit(const TetMesh& mesh);  // regions become element references
std::string formatVega(const TetMesh& mesh);   // materials and regions as *MATERIAL/*SET/*REGION
std::pair<std::string, std::string> formatTetGen(const TetMesh& mesh);  // {.node, .ele}, 1-based, region attribute

// What writing `mesh` to `path` (its extension's format) would drop, one sentence each: materials
// (only .veg holds them), and regions where .veg has no materials to hold them by.
std::vector<std::string> droppedByFormat(const std::string& path, const TetMesh& mesh);

// Writes `mesh` to `path` in the format its extension names (.vtu .vtk .msh .mesh .veg .node/.ele).
// Point fields are only kept by .vtu and .vtk; other formats refuse them with MeshError.
void writeMeshFile(const std::string& path, const TetMesh& mesh, const std::vector<PointField>& fields = {},
                   MeshFormat format = MeshFormat::Auto);

} // namespace quiver
