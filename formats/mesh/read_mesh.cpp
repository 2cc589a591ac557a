#include "formats/mesh/read_mesh.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/mesh_error.h"

namespace quiver {

namespace fs = std::filesystem;

std::ifstream openForReading(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw MeshError(path + ": cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshError(path + ": cannot open: " + std::strerror(errno));
  return in;
}

std::string readFileBytes(const std::string& path) {
  std::ifstream in = openForReading(path);
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) throw MeshError(path + ": read error");
  return buf.str();
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

MeshFormat detectMeshFormat(const std::string& path, std::string_view head) {
  const std::string ext = lowerExtension(path);
  if (ext == ".node" || ext == ".ele") return MeshFormat::TetGen;
  if (ext == ".msh") return MeshFormat::Gmsh;
  if (ext == ".veg") return MeshFormat::Vega;
  if (ext == ".vtk") return MeshFormat::VtkLegacy;
  if (ext == ".vtu") return MeshFormat::Vtu;
  if (ext == ".mesh") {
    size_t first = head.find_first_not_of(" \t\r\n");
    return first != std::string_view::npos && head.substr(first, 4) == "MFEM" ? MeshFormat::Mfem : MeshFormat::Medit;
  }
  return MeshFormat::Auto;
}

const char* meshFormatName(MeshFormat f) {
  switch (f) {
    case MeshFormat::TetGen: return "TetGen .node/.ele";
    case MeshFormat::Gmsh: return "Gmsh .msh";
    case MeshFormat::Medit: return "Medit .mesh";
    case MeshFormat::Mfem: return "MFEM .mesh";
    case MeshFormat::Vega: return "Vega .veg";
    case MeshFormat::VtkLegacy: return "VTK legacy .vtk";
    case MeshFormat::Vtu: return "VTK XML .vtu";
    case MeshFormat::Auto: break;
  }
  return "unknown";
}

RawMesh readMeshFile(const std::string& path, MeshFormat format) {
  std::error_code ec;
  const std::string ext = lowerExtension(path);
  const bool tetgenName = ext == ".node" || ext == ".ele" ||
                          (ext.empty() && !fs::exists(path, ec) && fs::exists(path + ".node", ec));
  if (format == MeshFormat::TetGen || (format == MeshFormat::Auto && tetgenName)) {
    fs::path stem = (ext == ".node" || ext == ".ele") ? fs::path(path).replace_extension() : fs::path(path);
    std::string node = stem.string() + ".node", ele = stem.string() + ".ele";
    return parseTetGen(readFileBytes(node), readFileBytes(ele), node, ele);
  }
  std::string bytes = readFileBytes(path);
  if (format == MeshFormat::Auto) format = detectMeshFormat(path, std::string_view(bytes).substr(0, 256));
  switch (format) {
    case MeshFormat::Gmsh: return parseGmsh(bytes, path);
    case MeshFormat::Medit: return parseMedit(bytes, path);
    case MeshFormat::Mfem: return parseMfem(bytes, path);
    case MeshFormat::Vega: return parseVega(bytes, path);
    case MeshFormat::VtkLegacy: return parseVtkLegacy(bytes, path);
    case MeshFormat::Vtu: return parseVtu(bytes, path);
    case MeshFormat::TetGen:
    case MeshFormat::Auto: break;
  }
  throw MeshError(path + ": unknown mesh format (extension '" + ext +
                  "'); supported: .node/.ele, .msh, .mesh (Medit or MFEM), .veg, .vtk, .vtu");
}

CheckedMesh loadMesh(const std::string& path, const MeshCheckOptions& options, MeshFormat format) {
  return checkMesh(readMeshFile(path, format), options);
}

FileVertexList readBouFile(const std::string& path) {
  FileVertexList list{path, {}, 1};
  for (int v : parseBou(readFileBytes(path), path, std::numeric_limits<int>::max())) list.indices.push_back(v);
  return list;
}

} // namespace quiver
