#include "formats/mesh/text_mesh_io.h"

#include <charconv>
#include <limits>

namespace quiver {

int readIndexCount(TextCursor& c, const char* what, int64_t minBytesEach) {
  int64_t n = c.count(what, minBytesEach);
  if (n > std::numeric_limits<int>::max())
    c.fail(std::string(what) + " " + std::to_string(n) + " is more than Quiver can index");
  return static_cast<int>(n);
}

Eigen::Vector3d readPoint(TextCursor& c) {
  Eigen::Vector3d p;
  p.x() = c.finiteReal("x coordinate");
  p.y() = c.finiteReal("y coordinate");
  p.z() = c.finiteReal("z coordinate");
  return p;
}

void expectEndOfFile(TextCursor& c, const char* after) {
  if (!c.atEnd()) c.fail("unexpected '" + printableToken(c.token("")) + "' after " + after);
}

int readVertexIndex(TextCursor& c, int64_t elementId, int64_t base, int64_t vertexCount) {
  int64_t index = c.integer("vertex index");
  if (index < base || index - base >= vertexCount) failVertexIndex(c.file(), c.line(), elementId, index, base, vertexCount);
  return static_cast<int>(index - base);
}

void failVertexIndex(const std::string& file, int64_t line, int64_t elementId, int64_t index, int64_t base,
                     int64_t vertexCount) {
  std::string message = file + ":" + std::to_string(line) + ": element " + std::to_string(elementId) +
                        ": vertex index " + std::to_string(index) + " is out of range ";
  if (vertexCount == 0)
    message += "(there are no vertices)";
  else
    message += "[" + std::to_string(base) + ", " + std::to_string(base + vertexCount - 1) + "]";
  throw MeshError(message);
}

void reportSkippedCells(RawMesh& raw, const std::vector<std::pair<std::string, int64_t>>& skipped) {
  int64_t total = 0;
  std::string kinds;
  for (const auto& [kind, n] : skipped) {
    if (n == 0) continue;
    total += n;
    kinds += (kinds.empty() ? "" : ", ") + kind + ": " + std::to_string(n);
  }
  if (total == 0) return;
  raw.report.skippedCells += total;
  raw.report.warnings.push_back(raw.source.file + ": skipped " + std::to_string(total) +
                                " elements that are not tetrahedra (" + kinds + ")");
}

void checkWritable(const TetMesh& mesh, const char* format) {
  const std::string prefix = std::string("cannot write ") + format + ": ";
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    if (!mesh.vertices[v].allFinite())
      throw MeshError(prefix + "vertex " + std::to_string(v) + " has a non-finite coordinate");
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    for (int v : mesh.tets[t])
      if (v < 0 || v >= mesh.vertexCount())
        throw MeshError(prefix + "tet " + std::to_string(t) + " has vertex index " + std::to_string(v) + " but there are " +
                        std::to_string(mesh.vertexCount()) + " vertices");
  if (!mesh.tetRegion.empty() && mesh.tetRegion.size() != mesh.tets.size())
    throw MeshError(prefix + std::to_string(mesh.tetRegion.size()) + " tet regions for " +
                    std::to_string(mesh.tets.size()) + " tets");
}

void appendReal(std::string& out, double v) {
  char buffer[32];
  // 32 characters hold any double's shortest form ("-2.2250738585072014e-308" is 24).
  char* end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
  out.append(buffer, end);
}

void appendInt(std::string& out, int64_t v) {
  char buffer[24];
  char* end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;  // 24 characters hold any int64
  out.append(buffer, end);
}

void appendPoint(std::string& out, const Eigen::Vector3d& p) {
  appendReal(out, p.x());
  out += ' ';
  appendReal(out, p.y());
  out += ' ';
  appendReal(out, p.z());
}

} // namespace quiver
