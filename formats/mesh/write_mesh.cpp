#include "formats/mesh/write_mesh.h"

#include <filesystem>
#include <set>

#include "formats/atomic_file.h"
#include "common/mesh_error.h"

namespace quiver {

std::vector<std::string> droppedByFormat(const std::string& path, const TetMesh& mesh) {
  const bool vega = detectMeshFormat(path, "") == MeshFormat::Vega;
  std::vector<std::string> dropped;
  if (!vega && !mesh.tetMaterial.empty()) {
    std::string names;
    for (const Material& m : mesh.materials) names += (names.empty() ? "" : ", ") + m.name;
    dropped.push_back(path + " cannot hold materials: the mesh's are dropped (" + names +
                      "; only .veg holds them, and the bake takes --E, --nu and --density)");
  }
  const std::set<int> regions(mesh.tetRegion.begin(), mesh.tetRegion.end());
  if (vega && mesh.tetMaterial.empty() && regions.size() > 1)
    dropped.push_back(path + " holds regions only as materials, and the mesh has none: its " +
                      std::to_string(regions.size()) + " regions are merged into one");
  return dropped;
}

void writeMeshFile(const std::string& path, const TetMesh& mesh, const std::vector<PointField>& fields,
                   MeshFormat format) {
  if (format == MeshFormat::Auto) format = detectMeshFormat(path, "");
  for (const auto& f : fields)
    if (f.values.size() != mesh.vertices.size())
      throw MeshError(path + ": point field '" + f.name + "' has " + std::to_string(f.values.size()) +
                      " values for " + std::to_string(mesh.vertices.size()) + " vertices");
  if (!fields.empty() && format != MeshFormat::Vtu && format != MeshFormat::VtkLegacy)
    throw MeshError(path + ": point fields (e.g. displacement) can only be written to .vtu or .vtk");
  try {
    switch (format) {
      case MeshFormat::Vtu: return writeFileAtomically(path, formatVtu(mesh, fields));
      case MeshFormat::VtkLegacy: return writeFileAtomically(path, formatVtkLegacy(mesh, fields));
      case MeshFormat::Gmsh: return writeFileAtomically(path, formatGmsh(mesh));
      case MeshFormat::Medit: return writeFileAtomically(path, formatMedit(mesh));
      case MeshFormat::Vega: return writeFileAtomically(path, formatVega(mesh));
      case MeshFormat::TetGen: {
        auto [node, ele] = formatTetGen(mesh);
        std::filesystem::path stem = std::filesystem::path(path).replace_extension();
        writeFileAtomically(stem.string() + ".node", node);
        return writeFileAtomically(stem.string() + ".ele", ele);
      }
      case MeshFormat::Mfem:
      case MeshFormat::Auto: break;
    }
  } catch (const std::runtime_error& e) {
    throw MeshError(e.what());
  }
  throw MeshError(path + ": cannot write this format (by extension: .vtu .vtk .msh .mesh .veg .node/.ele)");
}

} // namespace quiver
