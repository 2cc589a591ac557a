#include "precompute/checkpoint.h"

#include <stdexcept>

namespace quiver {

namespace {

const char* kHash = "input_hash";

void writeVector(Archive& archive, const std::string& dataset, const std::vector<double>& values) {
  archive.writeReplicated(dataset, {static_cast<int64_t>(values.size())}, values.data());
}

std::vector<double> readVector(const Archive& archive, const std::string& dataset) {
  std::vector<int64_t> shape;
  return archive.readReplicatedDouble(dataset, shape);
}

// Starts a stage group afresh: whatever a killed run left there goes first.
void resetGroup(Archive& archive, const std::string& group) {
  if (archive.exists(group)) archive.removeObject(group);
  archive.createGroup(group);
}

void finishGroup(Archive& archive, const std::string& group, const std::string& inputHash) {
  archive.setAttribute(group, kHash, inputHash);
  archive.flush();
}

} // namespace

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

void writeModes(Archive& archive, const LinearModes& modes, const DofLayout& layout, const std::string& inputHash) {
  resetGroup(archive, "/modes");
  writeVector(archive, "/modes/eigenvalues", modes.eigenvalues);
  writeVector(archive, "/modes/frequencies_hz", modes.frequenciesHz());
  writeVector(archive, "/modes/residuals", modes.residuals);
  writeVectors(archive, "/modes/vectors", modes.vectors, layout);
  archive.setAttribute("/modes", "rigid_modes_skipped", static_cast<int64_t>(modes.rigidSkipped));
  archive.setAttribute("/modes", "shift", modes.shift);
  finishGroup(archive, "/modes", inputHash);
}

LinearModes readModes(const Archive& archive, const DofLayout& layout) {
  LinearModes modes;
  modes.eigenvalues = readVector(archive, "/modes/eigenvalues");
  modes.residuals = readVector(archive, "/modes/residuals");
  modes.vectors = readVectors(archive, "/modes/vectors", layout);
  modes.rigidSkipped = static_cast<int>(archive.intAttribute("/modes", "rigid_modes_skipped"));
  modes.shift = archive.doubleAttribute("/modes", "shift");
  return modes;
}

void writeDerivatives(Archive& archive, const ModalDerivatives& derivatives, const DofLayout& layout,
                      const std::string& inputHash) {
  resetGroup(archive, "/derivatives");
  std::vector<int32_t> pairs;
  for (const auto& p : derivatives.pairs) pairs.insert(pairs.end(), {p[0], p[1]});
  archive.writeReplicated("/derivatives/pairs", {static_cast<int64_t>(derivatives.pairs.size()), 2}, pairs.data());
  writeVector(archive, "/derivatives/residuals", derivatives.residuals);
  writeVectors(archive, "/derivatives/vectors", derivatives.vectors, layout);
  finishGroup(archive, "/derivatives", inputHash);
}

ModalDerivatives readDerivatives(const Archive& archive, const DofLayout& layout) {
  ModalDerivatives d;
  std::vector<int64_t> shape;
  const std::vector<int64_t> pairs = archive.readReplicatedInt("/derivatives/pairs", shape);
  for (size_t p = 0; p + 1 < pairs.size(); p += 2)
    d.pairs.push_back({static_cast<int>(pairs[p]), static_cast<int>(pairs[p + 1])});
  d.residuals = readVector(archive, "/derivatives/residuals");
  d.vectors = readVectors(archive, "/derivatives/vectors", layout);
  return d;
}

void writeBasis(Archive& archive, const ReducedBasis& basis, const std::string& source, const DofLayout& layout,
                const std::string& inputHash) {
  resetGroup(archive, "/basis");
  writeVectors(archive, "/basis/vectors", basis.vectors, layout);
  writeVector(archive, "/basis/singular_values", basis.singularValues);
  archive.setAttribute("/basis", "source", source);
  archive.setAttribute("/basis", "orthonormality_error", basis.orthonormalityError);
  finishGroup(archive, "/basis", inputHash);
}

ReducedBasis readBasis(const Archive& archive, const DofLayout& layout) {
  ReducedBasis b;
  b.vectors = readVectors(archive, "/basis/vectors", layout);
  b.singularValues = readVector(archive, "/basis/singular_values");
  b.orthonormalityError = archive.doubleAttribute("/basis", "orthonormality_error");
  return b;
}

void writePolynomial(Archive& archive, const EnergyPolynomial& energy, const std::string& inputHash) {
  resetGroup(archive, "/polynomials");
  writeVector(archive, "/polynomials/energy_coefficients", energy.coefficients);
  archive.setAttribute("/polynomials", "r", static_cast<int64_t>(energy.r));
  finishGroup(archive, "/polynomials", inputHash);
}

EnergyPolynomial readPolynomial(const Archive& archive) {
  EnergyPolynomial energy;
  energy.r = static_cast<int>(archive.intAttribute("/polynomials", "r"));
  energy.coefficients = readVector(archive, "/polynomials/energy_coefficients");
  return energy;
}

} // namespace quiver
