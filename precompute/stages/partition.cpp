#include "precompute/stages/partition.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include <metis.h>

#include "common/surface.h"
#include "precompute/checkpoint.h"

namespace quiver {

namespace {

// The dual graph in METIS's CSR form: tets that share a face, found by sorting the faces
// (METIS_MeshToDual counts shared vertices instead, 0.25 s of a 97k-tet bake).
void dualGraph(const TetMesh& mesh, std::vector<idx_t>& xadj, std::vector<idx_t>& adjncy) {
  const auto faces = sortedFaces(mesh);
  std::vector<std::array<int, 2>> edges;  // every pair of tets on a face (more than two where it is not manifold)
  for (size_t first = 0, end = 0; first < faces.size(); first = end) {
    while (end < faces.size() && faces[end].first == faces[first].first) ++end;
    for (size_t a = first; a < end; ++a)
      for (size_t b = a + 1; b < end; ++b)
        edges.push_back({static_cast<int>(faces[a].second / 4), static_cast<int>(faces[b].second / 4)});
  }
  xadj.assign(mesh.tetCount() + 1, 0);
  for (const auto& e : edges) ++xadj[e[0] + 1], ++xadj[e[1] + 1];
  for (int t = 0; t < mesh.tetCount(); ++t) xadj[t + 1] += xadj[t];
  adjncy.resize(2 * edges.size());
  std::vector<idx_t> next(xadj.begin(), xadj.end() - 1);
  for (const auto& e : edges) adjncy[next[e[0]]++] = e[1], adjncy[next[e[1]]++] = e[0];
}

} // namespace

Partition partitionMesh(const TetMesh& mesh, const PartitionSettings& settings) {
  Partition p;
  const int ne = mesh.tetCount(), nn = mesh.vertexCount();
  p.tetPart.assign(ne, 0);
  if (settings.parts > 1) {
    if (settings.parts > ne)
      throw std::runtime_error("cannot split " + std::to_string(ne) + " tets into " + std::to_string(settings.parts) + " parts");
    std::vector<idx_t> xadj, adjncy;
    dualGraph(mesh, xadj, adjncy);
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_SEED] = settings.seed;
    options[METIS_OPTION_NUMBERING] = 0;
    idx_t nvtxs = ne, ncon = 1, nparts = settings.parts, objval = 0;
    std::vector<idx_t> part(ne);
    const int status = METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), nullptr, nullptr, nullptr,
                                           &nparts, nullptr, nullptr, options, &objval, part.data());
    if (status != METIS_OK) throw std::runtime_error("METIS_PartGraphKway failed with status " + std::to_string(status));
    std::copy(part.begin(), part.end(), p.tetPart.begin());
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
