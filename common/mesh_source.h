#pragma once
// Where each vertex and tet of a loaded mesh came from, so that later checks can point at the
// file, the line (or byte offset) and the element's own id.
#include <cstdint>
#include <string>
#include <vector>

#include "common/tet_mesh.h"

namespace quiver {

enum class SourcePositionKind { Line, ByteOffset, Record };

struct MeshSource {
  std::string file;                                       // path as given by the user
  SourcePositionKind positionKind = SourcePositionKind::Line;
  std::vector<int64_t> tetPosition;                       // line (1-based), byte offset or record index
  std::vector<int64_t> tetFileId;                         // the element's id as written in the file
  std::vector<int64_t> vertexFileId;                      // the vertex's id as written in the file

  void addTet(int64_t position, int64_t fileId) {
    tetPosition.push_back(position);
    tetFileId.push_back(fileId);
  }
  // "beam.msh:120: element 45" — the prefix of a message about tet t (0-based, in load order).
  std::string describeTet(size_t t) const;
  // "beam.msh: vertex 17" — vertex v by its id in the file.
  std::string describeVertex(size_t v) const;
};

// What a reader returns before validation.
struct MeshReadReport {
  std::vector<std::string> warnings; // each complete, naming the file
  int64_t skippedCells = 0;          // non-tet cells (triangles, lines, ...) ignored
};

// A mesh as read, before validation (common/mesh_checks.h): its tets, where each came from, and
// what the reader noticed.
struct RawMesh {
  TetMesh mesh;
  MeshSource source;
  MeshReadReport report;
};

} // namespace quiver
