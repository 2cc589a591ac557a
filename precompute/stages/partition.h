#pragma once
// Stage "partition": METIS splits the tets into one part per MPI rank (dual graph: tets that share
// a face are neighbours), and each vertex goes to the lowest-numbered part among its tets. Every
// rank computes the same partition from the same mesh, so no communication is needed.
#include <vector>

#include "common/tet_mesh.h"
#include "precompute/archive/archive.h"

namespace quiver {

struct PartitionSettings {
  int parts = 1;   // number of parts (MPI ranks)
  int seed = 17;   // METIS random seed: fixed so every rank and every run agree
};

struct Partition {
  std::vector<int> tetPart;     // per tet: owning part
  std::vector<int> vertexPart;  // per vertex: owning part
  int cutFaces = 0;             // faces shared by tets of different parts
};

// Throws std::runtime_error when METIS fails.
Partition partitionMesh(const TetMesh& mesh, const PartitionSettings& settings);

// Checkpoint: group /partition, rewritten on every run; the bake never reads it back.
void writePartition(Archive& archive, const Partition& partition, int ranks);

} // namespace quiver
