#include "formats/mesh/write_mesh.h"

#include <filesystem>

#include "formats/atomic_file.h"
#include "common/mesh_error.h"

namespace quiver {

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
