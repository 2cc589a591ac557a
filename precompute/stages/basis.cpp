#include "precompute/stages/basis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "common/rigid_body.h"
#include "formats/npy.h"
#include "precompute/checkpoint.h"
#include "precompute/input_hash.h"
#include "precompute/distributed_dense.h"

namespace quiver {

namespace {

double orthonormalityError(Mat mass, const DofLayout& layout, const Eigen::MatrixXd& U) {
  const Eigen::MatrixXd gram = innerProducts(U, multiply(mass, U, layout), layout.comm());
  return (gram - Eigen::MatrixXd::Identity(gram.rows(), gram.cols())).cwiseAbs().maxCoeff();
}

} // namespace

double massOrthonormalize(Mat mass, const DofLayout& layout, Eigen::MatrixXd& U) {
  // Two passes: the second removes what round-off left of the first (as in Gram-Schmidt twice).
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::MatrixXd gram = innerProducts(U, multiply(mass, U, layout), layout.comm());
    Eigen::LLT<Eigen::MatrixXd> llt(gram);
    if (llt.info() != Eigen::Success || !(llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 1e-8 * std::sqrt(gram.diagonal().maxCoeff())))
      throw std::runtime_error("the basis vectors are not linearly independent in the mass inner product");
    U = llt.matrixL().solve(U.transpose()).transpose();
  }
  return orthonormalityError(mass, layout, U);
}

const char* basisKindName(BasisKind kind) {
  switch (kind) {
    case BasisKind::Pca: return "pca";
    case BasisKind::KeepModes: return "keep-modes";
    case BasisKind::Modes: return "modes";
  }
  return "?";
}

namespace {

// The weight Barbič & James give derivative (i, j), sqrt 2 for the pair it stands for twice.
double derivativeWeight(const LinearModes& modes, int i, int j) {
  const double l1 = modes.eigenvalues[0];
  return (i == j ? 1.0 : std::sqrt(2.0)) * l1 * l1 / (modes.eigenvalues[i] * modes.eigenvalues[j]);
}

// Fewer vectors than asked: the largest basis the recipe gives, with a warning, or an error.
int achievableRank(int wanted, int available, const BasisSettings& settings, const std::string& why,
                   std::string& warning) {
  if (available >= wanted) return wanted;
  const std::string text = "basis (" + std::string(basisKindName(settings.kind)) + "): " + why + "; r = " +
                           std::to_string(available) + " instead of " + std::to_string(wanted);
  if (settings.exactRank || available < 1) throw std::runtime_error(text + " (--exact-rank: refused)");
  warning = text;
  return available;
}

// Mass-PCA through the small Gram matrix A^T M A = V D V^T: U = A V_r D_r^{-1/2}. A derivative is
// a displacement per squared amplitude, a mode one per amplitude: each derivative is taken at
// `amplitude` so that both are displacements and the set is the same whatever the units.
Eigen::MatrixXd massPca(Mat mass, const DofLayout& layout, const LinearModes& modes,
                        const ModalDerivatives& derivatives, double amplitude, const BasisSettings& settings,
                        ReducedBasis& out) {
  const int k = static_cast<int>(modes.eigenvalues.size());
  const int m = k + static_cast<int>(derivatives.pairs.size());
  const double l1 = modes.eigenvalues[0];
  Eigen::MatrixXd A(layout.localDofs(), m);
  for (int i = 0; i < k; ++i) A.col(i) = modes.vectors.col(i) * (l1 / modes.eigenvalues[i]);
  for (size_t p = 0; p < derivatives.pairs.size(); ++p) {
    const auto [i, j] = derivatives.pairs[p];
    A.col(k + static_cast<Eigen::Index>(p)) =
        derivatives.vectors.col(static_cast<Eigen::Index>(p)) * (amplitude * derivativeWeight(modes, i, j));
  }
  const Eigen::MatrixXd gram = innerProducts(A, multiply(mass, A, layout), layout.comm());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
  if (eig.info() != Eigen::Success) throw std::runtime_error("mass-PCA: the eigen-decomposition failed");
  for (int i = m - 1; i >= 0; --i) out.singularValues.push_back(std::sqrt(std::max(eig.eigenvalues()[i], 0.0)));
  int resolved = 0;
  while (resolved < m && out.singularValues[resolved] > 1e-7 * out.singularValues[0]) ++resolved;
  const int r = achievableRank(settings.rank, resolved, settings,
                               "only " + std::to_string(resolved) + " independent directions above 1e-7 of the largest",
                               out.warning);
  Eigen::MatrixXd V = eig.eigenvectors().rightCols(r).rowwise().reverse();
  for (int i = 0; i < r; ++i) V.col(i) /= out.singularValues[i];
  return A * V;
}

// The modes, then derivatives by weight, each M-orthogonalised against the basis so far (twice,
// for the digits) and kept while what is left of it is above 1e-6 of its M-norm.
Eigen::MatrixXd modesThenDerivatives(Mat mass, const DofLayout& layout, const LinearModes& modes,
                                     const ModalDerivatives& derivatives, const BasisSettings& settings,
                                     std::string& warning) {
  const int k = static_cast<int>(modes.eigenvalues.size());
  const int first = std::min(k, settings.rank);
  Eigen::MatrixXd U = modes.vectors.leftCols(first);
  std::vector<size_t> order(derivatives.pairs.size());
  for (size_t p = 0; p < order.size(); ++p) order[p] = p;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return derivativeWeight(modes, derivatives.pairs[a][0], derivatives.pairs[a][1]) >
           derivativeWeight(modes, derivatives.pairs[b][0], derivatives.pairs[b][1]);
  });
  for (size_t p : order) {
    if (U.cols() >= settings.rank) break;
    Eigen::VectorXd x = derivatives.vectors.col(static_cast<Eigen::Index>(p));
    const double size = std::sqrt(innerProducts(x, multiply(mass, x, layout), layout.comm())(0, 0));
    if (!(size > 0)) continue;
    x /= size;
    for (int pass = 0; pass < 2; ++pass) x -= U * innerProducts(U, multiply(mass, x, layout), layout.comm());
    const double left = std::sqrt(innerProducts(x, multiply(mass, x, layout), layout.comm())(0, 0));
    if (!(left > 1e-6)) continue;
    U.conservativeResize(Eigen::NoChange, U.cols() + 1);
    U.col(U.cols() - 1) = x / left;
  }
  achievableRank(settings.rank, static_cast<int>(U.cols()), settings,
                 "the " + std::to_string(k) + " modes and their derivatives give only " + std::to_string(U.cols()) +
                     " independent directions",
                 warning);
  return U;
}

} // namespace

double objectExtent(const TetMesh& mesh, const std::vector<Material>& perTet) {
  return std::sqrt(restMoments(mesh, perTet).secondMoment.trace());
}

ReducedBasis buildBasis(Mat mass, const DofLayout& layout, const LinearModes& modes,
                        const ModalDerivatives& derivatives, double extent, const BasisSettings& settings) {
  if (settings.rank < 1) throw std::runtime_error("basis rank r must be at least 1");
  const double amplitude = settings.pcaAmplitude * extent;
  if (settings.kind == BasisKind::Pca && !(amplitude > 0 && std::isfinite(amplitude)))
    throw std::runtime_error("basis (pca): --pca-amplitude " + shortNumber(settings.pcaAmplitude) +
                             " times the object's extent " + shortNumber(extent) + " is not a positive finite amplitude");
  ReducedBasis out;
  const int k = static_cast<int>(modes.eigenvalues.size());
  switch (settings.kind) {
    case BasisKind::Pca: out.vectors = massPca(mass, layout, modes, derivatives, amplitude, settings, out); break;
    case BasisKind::KeepModes:
      out.vectors = modesThenDerivatives(mass, layout, modes, derivatives, settings, out.warning);
      break;
    case BasisKind::Modes:
      out.vectors = modes.vectors.leftCols(
          achievableRank(settings.rank, k, settings, "only " + std::to_string(k) + " modes were baked", out.warning));
      break;
  }
  out.orthonormalityError = massOrthonormalize(mass, layout, out.vectors);
  layout.orientColumns(out.vectors);
  if (!(out.orthonormalityError <= settings.maxOrthonormalityError))
    throw std::runtime_error("basis: max |U^T M U - I| = " + std::to_string(out.orthonormalityError) +
                             " is above the limit");
  return out;
}

ReducedBasis importBasis(Mat mass, const DofLayout& layout, Eigen::MatrixXd rows, bool& wasOrthonormal) {
  wasOrthonormal = orthonormalityError(mass, layout, rows) <= 1e-8;
  ReducedBasis out;
  out.vectors = std::move(rows);
  out.orthonormalityError = massOrthonormalize(mass, layout, out.vectors);
  return out;
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

std::string basisInputHash(const std::string& vectorsHash, const BasisSettings& settings) {
  return InputHash()
      .add(vectorsHash)
      .add(settings.rank)
      .add(std::string(basisKindName(settings.kind)))
      .add(settings.exactRank)
      .add(settings.kind == BasisKind::Pca ? settings.pcaAmplitude : 0.0)  // the others ignore it
      .add(kBasisVersion)
      .hex();
}

std::string userBasisInputHash(const std::string& meshHash, const std::string& spec) {
  return InputHash().add(meshHash).add(spec).add(kUserBasisVersion).hex();
}

std::string describeBasis(const ReducedBasis& basis) {
  return "r = " + std::to_string(basis.vectors.cols()) + ", max |U^T M U - I| = " + shortNumber(basis.orthonormalityError);
}

// The user basis as a full 3n x r matrix in the loaded mesh's vertex order.
Eigen::MatrixXd loadUserBasis(MPI_Comm comm, const std::string& spec, const CheckedMesh& mesh) {
  const int64_t fileRows = 3 * static_cast<int64_t>(mesh.loadedVertex.size());
  std::vector<int64_t> shape;
  std::vector<double> data;
  const size_t colon = spec.find(".h5:");
  if (colon != std::string::npos) {
    Archive user(comm, spec.substr(0, colon + 3), Archive::Mode::ReadOnly);
    data = user.readReplicatedDouble(spec.substr(colon + 4), shape);
  } else {
    NpyArray a = readNpy(spec);
    shape = a.shape;
    data = std::move(a.data);
  }
  // (3N, r) as numpy users write it, or (r, N, 3) as the archive stores vectors; N in file order.
  const int64_t N = static_cast<int64_t>(mesh.loadedVertex.size());
  const bool columns = shape.size() == 2 && shape[0] == fileRows;
  const bool slices = shape.size() == 3 && shape[1] == N && shape[2] == 3;
  if (!columns && !slices)
    throw std::runtime_error(spec + ": a basis must have shape (3 x " + std::to_string(N) + " vertices, r) = (" +
                             std::to_string(fileRows) + ", r), or (r, " + std::to_string(N) + ", 3)");
  const int64_t r = columns ? shape[1] : shape[0];
  // A NaN once surfaced as "not linearly independent", from the orthonormalisation.
  for (size_t i = 0; i < data.size(); ++i)
    if (!std::isfinite(data[i]))
      throw std::runtime_error(spec + ": entry " + std::to_string(i) + " (in storage order) is not finite");
  Eigen::MatrixXd full(3 * static_cast<int64_t>(mesh.fileVertex.size()), r);
  for (size_t v = 0; v < mesh.fileVertex.size(); ++v)
    for (int c = 0; c < 3; ++c) {
      const int64_t row = 3 * mesh.fileVertex[v] + c;
      for (int64_t j = 0; j < r; ++j) full(3 * v + c, j) = columns ? data[row * r + j] : data[j * fileRows + row];
    }
  return full;
}

ReducedBasis bakeBasis(const BakeContext& ctx, const BasisRequest& request, const Eigen::MatrixXd& user, Mat mass,
                       const DofLayout& layout, const LinearModes& modes, const ModalDerivatives& derivatives,
                       double extent, Archive& archive, const std::string& inputHash) {
  ReducedBasis basis;
  std::string source;
  if (request.userBasis.empty()) {
    basis = buildBasis(mass, layout, modes, derivatives, extent, request.settings);
    source = request.settings.kind == BasisKind::Pca ? "modes+derivatives" : basisKindName(request.settings.kind);
  } else {
    bool wasOrthonormal = true;
    basis = importBasis(mass, layout, layout.localRowsOf(user), wasOrthonormal);
    if (!wasOrthonormal) basis.warning = request.userBasis + " was not M-orthonormal; it was orthonormalised";
    source = request.userBasis;
  }
  if (!basis.warning.empty() && ctx.rank() == 0) std::fprintf(stderr, "quiver-bake: warning: %s\n", basis.warning.c_str());
  writeBasis(archive, basis, source, layout, inputHash);
  return basis;
}

} // namespace quiver
