#pragma once
// Validation of a freshly read mesh: every problem is reported with the file, the line (or byte
// offset) and the element, and nothing is silently repaired except what the options allow.
#include <string>
#include <vector>

#include "common/mesh_source.h"

namespace quiver {

struct MeshCheckOptions {
  bool fixOrientation = false;        // flip inverted tets (with a warning) instead of refusing the mesh
  double degenerateTolerance = 1e-6;  // normalised volume 6*sqrt(2)*|V| / l_rms^3 (1 for a regular tet) below this is degenerate
};

struct CheckedMesh {
  TetMesh mesh;                    // valid: finite, no degenerate/inverted/duplicate tets, no unreferenced vertices
  std::vector<int> fileVertex;     // loaded vertex -> its 0-based index in the file's vertex order
  std::vector<int> loadedVertex;   // file vertex -> loaded index, -1 where it was dropped as unreferenced
  std::vector<std::string> warnings;
  int64_t skippedCells = 0;        // non-tet cells the reader skipped
  int flippedTets = 0;             // inverted tets flipped under fixOrientation
};

// Throws MeshError on the first problem that cannot be fixed (several of one kind are summarised
// in one message that names the first few).
CheckedMesh checkMesh(RawMesh raw, const MeshCheckOptions& options = {});

} // namespace quiver
