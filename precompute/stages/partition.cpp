#include "precompute/stages/partition.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <metis.h>

#include "precompute/checkpoint.h"

namespace quiver {

Partition partitionMesh(const TetMesh& mesh, const PartitionSettings& settings) {
  Partition p;
  const int ne = mesh.tetCount(), nn = mesh.vertexCount();
  p.tetPart.assign(ne, 0);
  if (settings.parts > 1) {
    if (settings.parts > ne)
      throw std::runtime_error("cannot split " + std::to_string(ne) + " tets into " + std::to_string(settings.parts) + " parts");
    std::vector<idx_t> eptr(ne + 1), eind(4 * static_cast<size_t>(ne)), npart(nn);
    for (int t = 0; t <= ne; ++t) eptr[t] = 4 * t;
    for (int t = 0; t < ne; ++t)
      for (int k = 0; k < 4; ++k) eind[4 * t + k] = mesh.tets[t][k];
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_SEED] = settings.seed;
    options[METIS_OPTION_NUMBERING] = 0;
    idx_t nel = ne, nnodes = nn, ncommon = 3, nparts = settings.parts, objval = 0;
    std::vector<idx_t> epart(ne);
    int status = METIS_PartMeshDual(&nel, &nnodes, eptr.data(), eind.data(), nullptr, nullptr, &ncommon, &nparts,
                                    nullptr, options, &objval, epart.data(), npart.data());
    if (status != METIS_OK) throw std::runtime_error("METIS_PartMeshDual failed with status " + std::to_string(status));
    std::copy(epart.begin(), epart.end(), p.tetPart.begin());
    p.cutFaces = static_cast<int>(objval);
  }
  p.vertexPart.assign(nn, settings.parts);
  for (int t = 0; t < ne; ++t)
    for (int v : mesh.tets[t]) p.vertexPart[v] = std::min(p.vertexPart[v], p.tetPart[t]);
  return p;
}

void writePartition(Archive& archive, const Partition& partition, int ranks) {
  resetGroup(archive, "/partition");
  archive.writeReplicated("/partition/tet_part", {static_cast<int64_t>(partition.tetPart.size())},
                          partition.tetPart.data());
  archive.writeReplicated("/partition/vertex_part", {static_cast<int64_t>(partition.vertexPart.size())},
                          partition.vertexPart.data());
  archive.setAttribute("/partition", "ranks", static_cast<int64_t>(ranks));
  archive.flush();
}

} // namespace quiver
