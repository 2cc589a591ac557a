#include "precompute/checkpoint.h"

#include <stdexcept>

namespace quiver {

namespace {
const char* kHash = "input_hash";
} // namespace

void writeVector(Archive& archive, const std::string& dataset, const std::vector<double>& values) {
  archive.writeReplicated(dataset, {static_cast<int64_t>(values.size())}, values.data());
}

std::vector<double> readVector(const Archive& archive, const std::string& dataset) {
  std::vector<int64_t> shape;
  return archive.readReplicatedDouble(dataset, shape);
}

void resetGroup(Archive& archive, const std::string& group) {
  if (archive.exists(group)) archive.removeObject(group);
  archive.createGroup(group);
}

void finishGroup(Archive& archive, const std::string& group, const std::string& inputHash) {
  archive.setAttribute(group, kHash, inputHash);
  archive.flush();
}

std::string storedInputHash(const Archive& archive, const std::string& group) {
  if (!archive.exists(group) || !archive.hasAttribute(group, kHash)) return "";
  return archive.stringAttribute(group, kHash);
}

void writeVectors(Archive& archive, const std::string& dataset, const Eigen::MatrixXd& local, const DofLayout& layout) {
  const std::vector<double> slab = layout.toVertexSlab(local);
  archive.writeSlab(dataset, {local.cols(), layout.vertexCount(), 3}, 1, layout.vertexSlabStart(),
                    layout.vertexSlabCount(), slab.data());
}

Eigen::MatrixXd readVectors(const Archive& archive, const std::string& dataset, const DofLayout& layout) {
  std::vector<int64_t> shape;
  const std::vector<double> all = archive.readReplicatedDouble(dataset, shape);
  if (shape.size() != 3 || shape[1] != layout.vertexCount() || shape[2] != 3)
    throw std::runtime_error(archive.path() + ": " + dataset + ": expected shape (columns, " +
                             std::to_string(layout.vertexCount()) + ", 3)");
  const int64_t cols = shape[0], n = shape[1];
  Eigen::MatrixXd full(3 * n, cols);
  for (int64_t j = 0; j < cols; ++j)
    for (int64_t r = 0; r < 3 * n; ++r) full(r, j) = all[j * 3 * n + r];
  return layout.localRowsOf(full);
}

void writeInputs(Archive& archive, const CheckedMesh& mesh, const std::string& sourceFile,
                 const std::vector<Material>& perTet, const std::vector<int>& fixedVertices,
                 const Partition& partition, int ranks) {
  const TetMesh& m = mesh.mesh;
  const int64_t n = m.vertexCount(), t = m.tetCount();
  resetGroup(archive, "/mesh");
  std::vector<double> xyz;
  for (const auto& x : m.vertices) xyz.insert(xyz.end(), {x.x(), x.y(), x.z()});
  archive.writeReplicated("/mesh/vertices", {n, 3}, xyz.data());
  std::vector<int32_t> tets;
  for (const Tet& tet : m.tets) tets.insert(tets.end(), tet.begin(), tet.end());
  archive.writeReplicated("/mesh/tets", {t, 4}, tets.data());
  archive.writeReplicated("/mesh/tet_region", {t}, m.tetRegion.data());
  const std::vector<int64_t> fileVertex(mesh.fileVertex.begin(), mesh.fileVertex.end());
  archive.writeReplicated("/mesh/file_vertex", {n}, fileVertex.data());
  archive.setAttribute("/mesh", "source_file", sourceFile);
  archive.setAttribute("/mesh", "file_vertex_count", static_cast<int64_t>(mesh.loadedVertex.size()));

  resetGroup(archive, "/material");
  std::vector<double> E, nu, rho;
  for (const Material& mat : perTet) {
    E.push_back(mat.youngsModulus);
    nu.push_back(mat.poissonRatio);
    rho.push_back(mat.density);
  }
  writeVector(archive, "/material/youngs_modulus", E);
  writeVector(archive, "/material/poisson_ratio", nu);
  writeVector(archive, "/material/density", rho);

  resetGroup(archive, "/constraints");
  archive.writeReplicated("/constraints/fixed_vertices", {static_cast<int64_t>(fixedVertices.size())},
                          fixedVertices.data());
  archive.setAttribute("/constraints", "fixed_dof_count", static_cast<int64_t>(3 * fixedVertices.size()));

  resetGroup(archive, "/partition");
  archive.writeReplicated("/partition/tet_part", {t}, partition.tetPart.data());
  archive.writeReplicated("/partition/vertex_part", {n}, partition.vertexPart.data());
  archive.setAttribute("/partition", "ranks", static_cast<int64_t>(ranks));
  archive.flush();
}

} // namespace quiver
