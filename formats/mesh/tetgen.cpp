// TetGen .node + .ele (0- or 1-based, linear or 10-node tetrahedra): reader and writer.
// Like TetGen's own reader, every record is one line; unlike it, fields beyond what the header
// declares are an error rather than ignored, so that a wrong header cannot shift the data.
#include <cmath>
#include <limits>

#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_mesh_io.h"
#include "formats/mesh/write_mesh.h"

namespace quiver {

namespace {

// Nothing follows the header's fields on its line.
void endHeader(TextCursor& c) {
  if (!c.atLineEnd()) c.fail("unexpected '" + printableToken(c.token("")) + "' at the end of the header");
}

// All `fields` of record `id` lie on `line`, where it starts, and nothing follows them there.
void endRecord(TextCursor& c, int line, const char* what, int64_t id, int64_t fields) {
  if (c.line() != line || !c.atLineEnd())
    throw MeshError(c.file() + ":" + std::to_string(line) + ": " + what + " " + std::to_string(id) + ": expected " +
                    std::to_string(fields) + " fields on the line, as the header declares");
}

// TetGen writes region attributes as reals ("1", "1.0", "-2"); they must be whole numbers.
int readRegion(TextCursor& c) {
  const std::string_view text = c.peekToken();
  const double r = c.real("region attribute");
  if (!(r == std::floor(r) && r >= std::numeric_limits<int>::min() && r <= std::numeric_limits<int>::max()))
    c.fail("region attribute '" + printableToken(text) + "' is not an integer");
  return static_cast<int>(r);
}

// Reads the .node file into raw.mesh.vertices; returns the numbering base (0 or 1) it uses.
int64_t readNodes(RawMesh& raw, std::string_view bytes, const std::string& file) {
  TextCursor c(bytes, file, '#');
  // Header fields after the count are optional: TetGen's defaults apply when the line ends early.
  const int n = readIndexCount(c, "vertex count", 8);  // "i x y z" and a separator
  const int64_t dimension = c.atLineEnd() ? 3 : c.integer("dimension");
  if (dimension != 3)
    c.fail("dimension " + std::to_string(dimension) + " is not supported: Quiver reads 3D tetrahedral meshes");
  const int64_t attributes = c.atLineEnd() ? 0 : c.count("attribute count", 2);
  const int64_t markers = c.atLineEnd() ? 0 : c.integerInRange("boundary marker flag", 0, 1);
  endHeader(c);

  int64_t base = 0;
  raw.mesh.vertices.reserve(n);
  raw.source.vertexFileId.reserve(n);
  for (int i = 0; i < n; ++i) {
    const int64_t id = c.integer("vertex number");
    const int line = c.line();
    if (i == 0) {
      if (id != 0 && id != 1) c.fail("the first vertex number must be 0 or 1, found " + std::to_string(id));
      base = id;
    } else if (id != base + i) {
      c.fail("vertex number " + std::to_string(id) + " is out of sequence: expected " + std::to_string(base + i));
    }
    raw.mesh.vertices.push_back(readPoint(c));
    for (int64_t a = 0; a < attributes; ++a) c.real("vertex attribute");
    if (markers) c.integer("boundary marker");
    endRecord(c, line, "vertex", id, 4 + attributes + markers);
    raw.source.vertexFileId.push_back(id);
  }
  expectEndOfFile(c, "the last vertex the header declares");
  return base;
}

} // namespace

RawMesh parseTetGen(std::string_view nodeBytes, std::string_view eleBytes, const std::string& nodeFile,
                    const std::string& eleFile) {
  RawMesh raw;
  raw.source.file = eleFile;  // tet positions are lines of the .ele
  raw.source.positionKind = SourcePositionKind::Line;
  const int64_t base = readNodes(raw, nodeBytes, nodeFile);
  const int64_t n = raw.mesh.vertexCount();

  TextCursor c(eleBytes, eleFile, '#');
  const int m = readIndexCount(c, "tetrahedron count", 10);  // "i a b c d" and a separator
  const int64_t nodesPerTet = c.atLineEnd() ? 4 : c.integer("nodes per tetrahedron");
  if (nodesPerTet != 4 && nodesPerTet != 10)
    c.fail("nodes per tetrahedron must be 4 or 10, found " + std::to_string(nodesPerTet));
  const int64_t attributes = c.atLineEnd() ? 0 : c.count("attribute count", 2);
  endHeader(c);

  TetMesh& mesh = raw.mesh;
  mesh.tets.reserve(m);
  mesh.tetRegion.reserve(m);
  raw.source.tetPosition.reserve(m);
  raw.source.tetFileId.reserve(m);
  for (int j = 0; j < m; ++j) {
    const int64_t id = c.integer("tetrahedron number");
    const int line = c.line();
    Tet tet;
    for (int& v : tet) v = readVertexIndex(c, id, base, n);
    for (int64_t k = 4; k < nodesPerTet; ++k) readVertexIndex(c, id, base, n);  // edge nodes: checked, unused
    mesh.tetRegion.push_back(attributes > 0 ? readRegion(c) : 0);
    for (int64_t a = 1; a < attributes; ++a) c.real("tetrahedron attribute");
    endRecord(c, line, "element", id, 1 + nodesPerTet + attributes);
    mesh.tets.push_back(tet);
    raw.source.addTet(line, id);
  }
  expectEndOfFile(c, "the last tetrahedron the header declares");
  if (nodesPerTet == 10 && m > 0)
    raw.report.warnings.push_back(eleFile + ": 10-node (quadratic) tetrahedra: only their 4 corner vertices are used");
  return raw;
}

std::pair<std::string, std::string> formatTetGen(const TetMesh& mesh) {
  checkWritable(mesh, "TetGen");
  std::string node;
  node.reserve(32 + 80 * mesh.vertices.size());
  appendInt(node, mesh.vertexCount());
  node += " 3 0 0\n";
  for (int i = 0; i < mesh.vertexCount(); ++i) {
    appendInt(node, i + 1);
    node += ' ';
    appendPoint(node, mesh.vertices[i]);
    node += '\n';
  }

  const bool regions = !mesh.tetRegion.empty();
  std::string ele;
  ele.reserve(32 + 56 * mesh.tets.size());
  appendInt(ele, mesh.tetCount());
  ele += regions ? " 4 1\n" : " 4 0\n";
  for (int t = 0; t < mesh.tetCount(); ++t) {
    appendInt(ele, t + 1);
    for (int v : mesh.tets[t]) {
      ele += ' ';
      appendInt(ele, v + 1);
    }
    if (regions) {
      ele += ' ';
      appendInt(ele, mesh.tetRegion[t]);
    }
    ele += '\n';
  }
  return {std::move(node), std::move(ele)};
}

} // namespace quiver
