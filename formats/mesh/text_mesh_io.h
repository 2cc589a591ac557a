#pragma once
// Routines shared by the plain-text mesh readers and writers (Medit, MFEM, TetGen): counts that
// can index an int, points, vertex references whose errors name the line and the element, the
// skipped-cell warning, and numbers printed so that they read back bit for bit.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_cursor.h"

namespace quiver {

// TextCursor::count(), also refusing counts too large for an int index.
int readIndexCount(TextCursor& c, const char* what, int64_t minBytesEach);

// Three finite coordinates x y z.
Eigen::Vector3d readPoint(TextCursor& c);

// Only blanks and comments remain; else "file:line: unexpected 'x' after <after>".
void expectEndOfFile(TextCursor& c, const char* after);

// One vertex reference of element `elementId`, which must lie in [base, base + vertexCount - 1];
// returns it 0-based. Errors read "file:line: element 12: vertex index 40 is out of range [1, 36]".
int readVertexIndex(TextCursor& c, int64_t elementId, int64_t base, int64_t vertexCount);

// The same error, for readers that can only check references once all vertices are read.
[[noreturn]] void failVertexIndex(const std::string& file, int64_t line, int64_t elementId, int64_t index,
                                  int64_t base, int64_t vertexCount);

// Adds to raw.report the cells a reader skipped, given as {kind, count}, with one warning naming
// the file when there were any: "f.mesh: skipped 14 elements that are not tetrahedra (Triangles: 12, Edges: 2)".
void reportSkippedCells(RawMesh& raw, const std::vector<std::pair<std::string, int64_t>>& skipped);

// Refuses (MeshError "cannot write <format>: ...") a mesh whose file would not read back: a
// non-finite coordinate, a vertex index out of range, or tetRegion neither empty nor one per tet.
void checkWritable(const TetMesh& mesh, const char* format);

// Appends the shortest decimal text that reads back as exactly `v`.
void appendReal(std::string& out, double v);
void appendInt(std::string& out, int64_t v);
void appendPoint(std::string& out, const Eigen::Vector3d& p);  // "x y z"

} // namespace quiver
