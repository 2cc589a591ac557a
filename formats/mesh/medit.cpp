// Medit / Gamma Mesh Format, ASCII .mesh (libMeshb's keyword layout): reader and writer.
// The binary .meshb variant is refused with a clear error.
#include <algorithm>
#include <cctype>
#include <limits>

#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_mesh_io.h"
#include "formats/mesh/write_mesh.h"

namespace quiver {

namespace {

// Sections read only to be skipped, with the fields of one record in 3D as libMeshb lays them out
// ('i' integer, 'r' real). Records of a `isCell` section are elements, counted in skippedCells.
struct SkippedSection {
  const char* name;
  const char* fields;
  bool isCell;
};

constexpr SkippedSection kSkippedSections[] = {
    {"Edges", "iii", true},
    {"Triangles", "iiii", true},
    {"Quadrilaterals", "iiiii", true},
    {"Prisms", "iiiiiii", true},
    {"Pyramids", "iiiiii", true},
    {"Hexahedra", "iiiiiiiii", true},
    {"EdgesP2", "iiii", true},
    {"TrianglesP2", "iiiiiii", true},
    {"QuadrilateralsQ2", "iiiiiiiiii", true},
    {"TetrahedraP2", "iiiiiiiiiii", true},
    {"HexahedraQ2", "iiiiiiiiiiiiiiiiiiiiiiiiiiii", true},
    {"Corners", "i", false},
    {"Ridges", "i", false},
    {"RequiredVertices", "i", false},
    {"RequiredEdges", "i", false},
    {"RequiredTriangles", "i", false},
    {"RequiredQuadrilaterals", "i", false},
    {"Normals", "rrr", false},
    {"Tangents", "rrr", false},
    {"NormalAtVertices", "ii", false},
    {"TangentAtVertices", "ii", false},
    {"NormalAtTriangleVertices", "iii", false},
    {"NormalAtQuadrilateralVertices", "iiii", false},
    {"TangentAtEdgeVertices", "iii", false},
};

// Medit keywords are case-sensitive, but files written by hand are accepted in any case.
bool isKeyword(std::string_view token, std::string_view keyword) {
  return token.size() == keyword.size() &&
         std::equal(token.begin(), token.end(), keyword.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
         });
}

class MeditReader {
public:
  MeditReader(std::string_view bytes, const std::string& file) : c_(bytes, file, '#') {
    raw_.source.file = file;
    raw_.source.positionKind = SourcePositionKind::Line;
  }

  RawMesh read() {
    const std::string_view first = c_.token("'MeshVersionFormatted'");
    if (!isKeyword(first, "MeshVersionFormatted"))
      c_.fail("expected 'MeshVersionFormatted', found '" + printableToken(first) + "'");
    c_.integerInRange("MeshVersionFormatted", 1, 4);
    for (;;) {
      const std::string_view keyword = c_.token("a section keyword or 'End'");
      if (isKeyword(keyword, "End")) break;
      if (isKeyword(keyword, "Dimension"))
        readDimension();
      else if (isKeyword(keyword, "Vertices"))
        readVertices();
      else if (isKeyword(keyword, "Tetrahedra"))
        readTetrahedra();
      else
        skipSection(keyword);
    }
    reportSkippedCells(raw_, skipped_);
    return std::move(raw_);
  }

private:
  void readDimension() {
    const int64_t dimension = c_.integer("Dimension");
    if (dimension != 3)
      c_.fail("Dimension " + std::to_string(dimension) + " is not supported: Quiver reads 3D tetrahedral meshes");
    haveDimension_ = true;
  }

  void readVertices() {
    if (!haveDimension_) c_.fail("'Vertices' before 'Dimension'");
    if (haveVertices_) c_.fail("a second 'Vertices' section");
    haveVertices_ = true;
    const int n = readIndexCount(c_, "vertex count", 8);  // "x y z ref" and a separator
    raw_.mesh.vertices.reserve(n);
    raw_.source.vertexFileId.reserve(n);
    for (int i = 0; i < n; ++i) {
      raw_.mesh.vertices.push_back(readPoint(c_));
      c_.integer("vertex reference");
      raw_.source.vertexFileId.push_back(i + 1);
    }
  }

  void readTetrahedra() {
    if (!haveVertices_) c_.fail("'Tetrahedra' before 'Vertices'");
    if (haveTets_) c_.fail("a second 'Tetrahedra' section");
    haveTets_ = true;
    const int m = readIndexCount(c_, "tetrahedron count", 10);  // "a b c d ref" and a separator
    TetMesh& mesh = raw_.mesh;
    const int64_t n = mesh.vertexCount();
    mesh.tets.reserve(m);
    mesh.tetRegion.reserve(m);
    raw_.source.tetPosition.reserve(m);
    raw_.source.tetFileId.reserve(m);
    for (int j = 1; j <= m; ++j) {
      Tet tet;
      tet[0] = readVertexIndex(c_, j, 1, n);
      const int line = c_.line();
      for (int k = 1; k < 4; ++k) tet[k] = readVertexIndex(c_, j, 1, n);
      mesh.tetRegion.push_back(static_cast<int>(c_.integerInRange(
          "tetrahedron reference", std::numeric_limits<int>::min(), std::numeric_limits<int>::max())));
      mesh.tets.push_back(tet);
      raw_.source.addTet(line, j);
    }
  }

  void skipSection(std::string_view keyword) {
    auto section = std::find_if(std::begin(kSkippedSections), std::end(kSkippedSections),
                                [&](const SkippedSection& s) { return isKeyword(keyword, s.name); });
    if (section == std::end(kSkippedSections))
      c_.fail("unsupported section '" + printableToken(keyword) +
              "' (Quiver reads Vertices and Tetrahedra and skips the usual element and geometry sections)");
    const std::string_view fields = section->fields;
    const int64_t n = c_.count(section->name, 2 * static_cast<int64_t>(fields.size()));
    for (int64_t r = 0; r < n; ++r)
      for (char field : fields) {
        if (field == 'i')
          c_.integer(section->name);
        else
          c_.real(section->name);
      }
    if (section->isCell) skipped_.emplace_back(section->name, n);
  }

  TextCursor c_;
  RawMesh raw_;
  std::vector<std::pair<std::string, int64_t>> skipped_;
  bool haveDimension_ = false, haveVertices_ = false, haveTets_ = false;
};

} // namespace

RawMesh parseMedit(std::string_view bytes, const std::string& file) {
  // Binary .meshb starts with the 32-bit integer 1 in either byte order; text never holds a NUL.
  if (bytes.substr(0, 64).find('\0') != std::string_view::npos)
    throw MeshError(file + ": looks like binary Medit (.meshb), which Quiver does not read: convert it to ASCII .mesh");
  return MeditReader(bytes, file).read();
}

std::string formatMedit(const TetMesh& mesh) {
  checkWritable(mesh, "Medit");
  std::string out;
  out.reserve(64 + 72 * mesh.vertices.size() + 48 * mesh.tets.size());
  out += "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n";
  appendInt(out, mesh.vertexCount());
  out += '\n';
  for (const Eigen::Vector3d& x : mesh.vertices) {
    appendPoint(out, x);
    out += " 0\n";
  }
  out += "\nTetrahedra\n";
  appendInt(out, mesh.tetCount());
  out += '\n';
  for (int t = 0; t < mesh.tetCount(); ++t) {
    for (int v : mesh.tets[t]) {
      appendInt(out, v + 1);
      out += ' ';
    }
    appendInt(out, mesh.tetRegion.empty() ? 0 : mesh.tetRegion[t]);
    out += '\n';
  }
  out += "\nEnd\n";
  return out;
}

} // namespace quiver
