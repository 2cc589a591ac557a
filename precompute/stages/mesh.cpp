#include "precompute/stages/mesh.h"

#include <cstdio>
#include <stdexcept>

#include "formats/mesh/read_mesh.h"
#include "precompute/checkpoint.h"
#include "precompute/input_hash.h"

namespace quiver {

namespace {

// The mesh's pieces (tets joined through shared vertices): each must be held by a fixed vertex,
// or, for a free object, be the only one; else K has more null directions than the rigid motions
// the bake accounts for, and the factorisation failed saying only "negative pivots".
void checkPieces(const MeshInputs& in, const std::string& path) {
  const TetMesh& m = in.mesh.mesh;
  std::vector<int> parent(static_cast<size_t>(m.vertexCount()));
  for (size_t v = 0; v < parent.size(); ++v) parent[v] = static_cast<int>(v);
  const auto root = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const Tet& t : m.tets)
    for (int k = 1; k < 4; ++k) parent[root(t[k])] = root(t[0]);
  std::vector<char> held(parent.size(), 0);
  for (int v : in.fixed) held[root(v)] = 1;
  int pieces = 0, loose = 0, firstLoose = -1;
  for (int v = 0; v < m.vertexCount(); ++v)
    if (root(v) == v) {
      ++pieces;
      if (!held[v] && !in.freeObject() && loose++ == 0) firstLoose = v;
    }
  const auto where = [&](int v) {
    const Eigen::Vector3d& x = m.vertices[v];
    char text[160];
    std::snprintf(text, sizeof text, "vertex %d (%g, %g, %g)", in.mesh.fileVertex[v], x.x(), x.y(), x.z());
    return std::string(text);
  };
  if (in.freeObject() && pieces > 1) {
    int second = -1;
    for (int v = 0; v < m.vertexCount() && second < 0; ++v)
      if (root(v) != root(0)) second = v;
    throw std::invalid_argument(path + ": " + std::to_string(pieces) + " separate pieces (no vertex joins them), the second at " +
                                where(second) + ": a free object must be one piece; bake each piece on its own");
  }
  if (loose > 0)
    throw std::invalid_argument(path + ": " + std::to_string(pieces) + " separate pieces (no vertex joins them), " +
                                std::to_string(loose) + " of them with no fixed vertex, the first at " + where(firstLoose) +
                                ": fix vertices of every piece, or bake each piece on its own");
}

} // namespace

MeshInputs loadMeshInputs(const MeshSettings& s) {
  MeshInputs in;
  in.mesh = loadMesh(s.path, s.checks);
  in.fixed = selectFixedVertices(in.mesh, s.fixed);
  in.perTet = resolveTetMaterials(in.mesh.mesh, s.fallback, s.material);
  for (const Material& m : in.perTet)
    if (std::string bad = checkMaterial(m); !bad.empty()) throw std::invalid_argument(s.path + ": " + bad);
  InputHash h;
  h.add(readFileBytes(s.path)).add(s.checks.fixOrientation).add(s.checks.degenerateTolerance).add(in.fixed);
  for (const Material& m : in.perTet) h.add(m.youngsModulus).add(m.poissonRatio).add(m.density);
  in.hash = h.hex();
  in.freeDofs = 3 * (static_cast<int64_t>(in.mesh.mesh.vertexCount()) - static_cast<int64_t>(in.fixed.size()));
  checkPieces(in, s.path);
  return in;
}

void warnAboutMesh(const BakeContext& ctx, const MeshInputs& in, const MeshSettings& s) {
  if (ctx.rank() != 0) return;
  for (const std::string& w : in.mesh.warnings) std::fprintf(stderr, "quiver-bake: warning: %s\n", w.c_str());
  if (in.mesh.mesh.materials.empty() && !(s.material.youngsModulus && s.material.poissonRatio && s.material.density))
    std::fprintf(stderr,
                 "quiver-bake: warning: %s defines no material; using E = %g Pa, nu = %g, density = %g kg/m^3 "
                 "where --E, --nu, --density do not say\n",
                 s.path.c_str(), in.perTet[0].youngsModulus, in.perTet[0].poissonRatio, in.perTet[0].density);
}

void writeMeshInputs(Archive& archive, const MeshInputs& in, const std::string& sourceFile) {
  const TetMesh& m = in.mesh.mesh;
  const int64_t n = m.vertexCount(), t = m.tetCount();
  resetGroup(archive, "/mesh");
  std::vector<double> xyz;
  for (const auto& x : m.vertices) xyz.insert(xyz.end(), {x.x(), x.y(), x.z()});
  archive.writeReplicated("/mesh/vertices", {n, 3}, xyz.data());
  std::vector<int32_t> tets;
  for (const Tet& tet : m.tets) tets.insert(tets.end(), tet.begin(), tet.end());
  archive.writeReplicated("/mesh/tets", {t, 4}, tets.data());
  archive.writeReplicated("/mesh/tet_region", {t}, m.tetRegion.data());
  const std::vector<int64_t> fileVertex(in.mesh.fileVertex.begin(), in.mesh.fileVertex.end());
  archive.writeReplicated("/mesh/file_vertex", {n}, fileVertex.data());
  archive.setAttribute("/mesh", "source_file", sourceFile);
  archive.setAttribute("/mesh", "file_vertex_count", static_cast<int64_t>(in.mesh.loadedVertex.size()));

  resetGroup(archive, "/material");
  std::vector<double> E, nu, rho;
  for (const Material& mat : in.perTet) {
    E.push_back(mat.youngsModulus);
    nu.push_back(mat.poissonRatio);
    rho.push_back(mat.density);
  }
  writeVector(archive, "/material/youngs_modulus", E);
  writeVector(archive, "/material/poisson_ratio", nu);
  writeVector(archive, "/material/density", rho);

  resetGroup(archive, "/constraints");
  archive.writeReplicated("/constraints/fixed_vertices", {static_cast<int64_t>(in.fixed.size())}, in.fixed.data());
  archive.setAttribute("/constraints", "fixed_dof_count", static_cast<int64_t>(3 * in.fixed.size()));
  archive.flush();
}

std::string describeMesh(const MeshInputs& in) {
  return std::to_string(in.mesh.mesh.vertexCount()) + " vertices, " + std::to_string(in.mesh.mesh.tetCount()) +
         " tets, " + std::to_string(in.fixed.size()) + " fixed vertices" +
         (in.freeObject() ? " (free object: the six rigid modes are skipped)" : "") + ", " +
         std::to_string(in.freeDofs) + " free DOFs";
}

} // namespace quiver
