// MFEM's own mesh format, "MFEM mesh v1.0" (and v1.2, the same plus an "mfem_mesh_end" tag) with
// straight (linear) vertices: reader. Curved meshes ("nodes"), non-conforming and NURBS meshes are refused.
#include <limits>

#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_mesh_io.h"

namespace quiver {

namespace {

// MFEM's Geometry::Type values 0..7 (fem/geom.hpp): name and vertex count.
struct Geometry {
  const char* name;
  int vertices;
};
constexpr Geometry kGeometries[] = {{"points", 1}, {"segments", 2}, {"triangles", 3}, {"squares", 4},
                                    {"tetrahedra", 4}, {"cubes", 8}, {"prisms", 6}, {"pyramids", 5}};
constexpr int kTetrahedron = 4;
constexpr int kGeometryCount = sizeof(kGeometries) / sizeof(kGeometries[0]);

// Reads one "attribute geometry v0 v1 ..." line's attribute and geometry.
std::pair<int, int> readElementHead(TextCursor& c) {
  const int attribute = static_cast<int>(
      c.integerInRange("attribute", std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
  const int geometry = static_cast<int>(c.integerInRange("geometry type", 0, kGeometryCount - 1));
  return {attribute, geometry};
}

} // namespace

RawMesh parseMfem(std::string_view bytes, const std::string& file) {
  RawMesh raw;
  raw.source.file = file;
  raw.source.positionKind = SourcePositionKind::Line;
  TextCursor c(bytes, file, '#');

  const std::string_view header = c.restOfLine();
  const bool v12 = header == "MFEM mesh v1.2";
  if (header != "MFEM mesh v1.0" && !v12)
    c.fail("expected 'MFEM mesh v1.0' or 'MFEM mesh v1.2' on the first line, found '" + printableToken(header) +
           "' (non-conforming, NURBS and other MFEM mesh versions are not supported)");

  c.expect("dimension");
  const int64_t dimension = c.integer("dimension");
  if (dimension != 3)
    c.fail("dimension " + std::to_string(dimension) + " is not supported: Quiver reads 3D tetrahedral meshes");

  c.expect("elements");
  const int elementCount = readIndexCount(c, "element count", 6);  // "attribute geometry v0" at least
  TetMesh& mesh = raw.mesh;
  mesh.tets.reserve(elementCount);
  mesh.tetRegion.reserve(elementCount);
  raw.source.tetPosition.reserve(elementCount);
  raw.source.tetFileId.reserve(elementCount);
  std::vector<std::pair<std::string, int64_t>> skipped;  // {geometry name, count}, by geometry type
  for (const Geometry& g : kGeometries) skipped.emplace_back(g.name, 0);
  for (int e = 1; e <= elementCount; ++e) {
    const auto [attribute, geometry] = readElementHead(c);
    const int line = c.line();
    if (geometry != kTetrahedron) {
      for (int k = 0; k < kGeometries[geometry].vertices; ++k) c.integer("vertex index");
      ++skipped[geometry].second;
      continue;
    }
    Tet tet;  // range-checked below, once the vertex count (which follows the elements) is known
    for (int& v : tet) v = readVertexIndex(c, e, 0, std::numeric_limits<int>::max());
    mesh.tets.push_back(tet);
    mesh.tetRegion.push_back(attribute);
    raw.source.addTet(line, e);
  }

  c.expect("boundary");
  const int64_t boundaryCount = c.count("boundary element count", 6);
  for (int64_t b = 0; b < boundaryCount; ++b) {
    const int geometry = readElementHead(c).second;
    for (int k = 0; k < kGeometries[geometry].vertices; ++k) c.integer("vertex index");
  }

  c.expect("vertices");
  const int n = readIndexCount(c, "vertex count", 6);  // "x y z" at least
  if (c.peekToken() == "nodes") {
    c.token("nodes");
    c.fail("curved MFEM meshes ('nodes' with a FiniteElementSpace) are not supported: Quiver reads meshes "
           "whose geometry is given by the 'vertices' coordinates");
  }
  const int64_t vertexDimension = c.integer("vertex dimension");
  if (vertexDimension != 3)
    c.fail("vertex dimension " + std::to_string(vertexDimension) + " is not supported: Quiver needs 3 coordinates");
  mesh.vertices.reserve(n);
  raw.source.vertexFileId.reserve(n);
  for (int i = 0; i < n; ++i) {
    mesh.vertices.push_back(readPoint(c));
    raw.source.vertexFileId.push_back(i);  // elements refer to vertices by 0-based index
  }
  if (v12)
    c.expect("mfem_mesh_end");
  else
    expectEndOfFile(c, "the vertex coordinates");

  for (size_t t = 0; t < mesh.tets.size(); ++t)
    for (int v : mesh.tets[t])
      if (v >= n) failVertexIndex(file, raw.source.tetPosition[t], raw.source.tetFileId[t], v, 0, n);

  reportSkippedCells(raw, skipped);
  return raw;
}

} // namespace quiver
