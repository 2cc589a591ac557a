#include "formats/mesh/vtk_common.h"

#include <cctype>
#include <charconv>
#include <climits>

#include "common/mesh_error.h"

namespace quiver::vtk {

namespace {
struct ScalarInfo {
  Scalar scalar;
  const char* xmlName;
  size_t bytes;
};
constexpr ScalarInfo kScalars[] = {
    {Scalar::Int8, "Int8", 1},       {Scalar::UInt8, "UInt8", 1},     {Scalar::Int16, "Int16", 2},
    {Scalar::UInt16, "UInt16", 2},   {Scalar::Int32, "Int32", 4},     {Scalar::UInt32, "UInt32", 4},
    {Scalar::Int64, "Int64", 8},     {Scalar::UInt64, "UInt64", 8},   {Scalar::Float32, "Float32", 4},
    {Scalar::Float64, "Float64", 8},
};

const ScalarInfo& info(Scalar s) { return kScalars[static_cast<int>(s)]; }

bool equalNoCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

const char* cellTypeName(int64_t type) {
  switch (type) {
  case 1: return "VTK_VERTEX";
  case 2: return "VTK_POLY_VERTEX";
  case 3: return "VTK_LINE";
  case 4: return "VTK_POLY_LINE";
  case 5: return "VTK_TRIANGLE";
  case 6: return "VTK_TRIANGLE_STRIP";
  case 7: return "VTK_POLYGON";
  case 8: return "VTK_PIXEL";
  case 9: return "VTK_QUAD";
  case 10: return "VTK_TETRA";
  case 11: return "VTK_VOXEL";
  case 12: return "VTK_HEXAHEDRON";
  case 13: return "VTK_WEDGE";
  case 14: return "VTK_PYRAMID";
  case 21: return "VTK_QUADRATIC_EDGE";
  case 22: return "VTK_QUADRATIC_TRIANGLE";
  case 23: return "VTK_QUADRATIC_QUAD";
  case 24: return "VTK_QUADRATIC_TETRA";
  case 25: return "VTK_QUADRATIC_HEXAHEDRON";
  case 42: return "VTK_POLYHEDRON";
  default: return "unknown type";
  }
}
} // namespace

size_t scalarBytes(Scalar s) { return info(s).bytes; }
bool isFloating(Scalar s) { return s == Scalar::Float32 || s == Scalar::Float64; }
const char* xmlScalarName(Scalar s) { return info(s).xmlName; }

bool parseXmlScalar(std::string_view name, Scalar& out) {
  for (const ScalarInfo& s : kScalars)
    if (name == s.xmlName) {
      out = s.scalar;
      return true;
    }
  return false;
}

bool isRegionArrayName(std::string_view name) {
  for (std::string_view known : {"region", "material", "gmsh:physical", "MaterialIds", "CellEntityIds"})
    if (equalNoCase(name, known)) return true;
  return false;
}

std::string nonIntegerRegionWarning(const std::string& where, std::string_view name) {
  return where + ": cell array '" + std::string(name) +
         "' has a floating-point type; regions need an integer type, so it is ignored";
}

void TetCollector::add(const CellList& cells, const std::vector<int64_t>& regions, int64_t pointBase,
                       int64_t pointCount, int64_t cellBase, const std::function<std::string(size_t)>& where) {
  TetMesh& mesh = out_.mesh;
  for (size_t c = 0; c < cells.types.size(); ++c) {
    if (cells.types[c] != kTetra) {
      ++skipped_[cells.types[c]];
      continue;
    }
    const int64_t begin = cells.offsets[c], size = cells.offsets[c + 1] - begin;
    if (size != 4) throw MeshError(where(c) + ": VTK_TETRA cell has " + std::to_string(size) + " points, not 4");
    Tet tet;
    for (int k = 0; k < 4; ++k) {
      const int64_t p = cells.connectivity[static_cast<size_t>(begin + k)];
      if (p < 0 || p >= pointCount)
        throw MeshError(where(c) + ": point index " + std::to_string(p) + " is out of range [0, " +
                        std::to_string(pointCount) + ")");
      tet[k] = static_cast<int>(pointBase + p);
    }
    const int64_t region = regions.empty() ? 0 : regions[c];
    if (region < INT_MIN || region > INT_MAX)
      throw MeshError(where(c) + ": region " + std::to_string(region) + " does not fit in an int");
    if (mesh.tets.size() >= static_cast<size_t>(INT_MAX)) throw MeshError(where(c) + ": too many tets");
    mesh.tets.push_back(tet);
    mesh.tetRegion.push_back(static_cast<int>(region));
    out_.source.addTet(cells.positions[c], cellBase + static_cast<int64_t>(c));
  }
}

void TetCollector::finish() {
  if (skipped_.empty()) return;
  std::string byType;
  int64_t total = 0;
  for (const auto& [type, count] : skipped_) {
    byType += (byType.empty() ? "" : ", ") + std::to_string(count) + " " + cellTypeName(type) + " (type " +
              std::to_string(type) + ")";
    total += count;
  }
  out_.report.skippedCells += total;
  out_.report.warnings.push_back(out_.source.file + ": skipped " + std::to_string(total) +
                                 " non-tetrahedral cells: " + byType);
}

void checkWritable(const TetMesh& mesh, const std::vector<PointField>& fields, const char* format) {
  if (!mesh.tetRegion.empty() && mesh.tetRegion.size() != mesh.tets.size())
    throw MeshError(std::string(format) + ": the mesh has " + std::to_string(mesh.tetRegion.size()) +
                    " tet regions for " + std::to_string(mesh.tets.size()) + " tets");
  for (const PointField& f : fields) {
    if (f.name.empty()) throw MeshError(std::string(format) + ": a point field has no name");
    if (f.values.size() != mesh.vertices.size())
      throw MeshError(std::string(format) + ": point field '" + f.name + "' has " + std::to_string(f.values.size()) +
                      " values for " + std::to_string(mesh.vertices.size()) + " vertices");
  }
}

void appendNumber(std::string& out, double v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, end);
}

void appendNumber(std::string& out, int64_t v) {
  char buf[24];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, end);
}

} // namespace quiver::vtk
