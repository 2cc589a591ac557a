#include "precompute/stages/modal_derivatives.h"

#include <algorithm>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "common/stvk_element.h"
#include "precompute/checkpoint.h"
#include "precompute/direct_solver.h"
#include "precompute/input_hash.h"
#include "precompute/distributed_dense.h"

namespace quiver {

namespace {

// -d^2R[phi_i, phi_j] for every pair i <= j, in the order of ModalDerivatives::pairs: this rank's
// rows (free DOFs x pairs). Each rank integrates every tet touching its rows, in tet order
// (DofLayout::ownsRowOf: the same bits on every rank count and every run; the tets on the
// partition's interface are integrated on each rank they touch), and adds its own rows in place,
// each DOF's pairs side by side (a tet adds 12 contiguous rows, not 12 x pairs scattered values).
Eigen::MatrixXd rightHandSides(const TetMesh& mesh, const std::vector<Material>& perTet, const DofLayout& layout,
                               const Eigen::MatrixXd& fullModes) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor modes = fullModes;  // a vertex's 3 rows of every mode contiguous
  const Eigen::Index k = modes.cols(), P = k * (k + 1) / 2;
  RowMajor own = RowMajor::Zero(layout.localDofs(), P);
  const TetElements elements = computeTetElements(mesh);
  Eigen::Matrix<double, 3, Eigen::Dynamic> modesOnTet(3, 4 * k);
  RowMajor values(12, P);
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const Tet& tet = mesh.tets[t];
    if (!layout.ownsRowOf(tet)) continue;
    for (Eigen::Index i = 0; i < k; ++i)
      for (int a = 0; a < 4; ++a) modesOnTet.col(4 * i + a) = modes.block<3, 1>(3 * tet[a], i);
    stvkElementForceHessiansAtRest(modesOnTet, elements.gradients[t], elements.volume[t], perTet[t].lambda(),
                                   perTet[t].mu(), values.data(), P);
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) {
        const int64_t dof = layout.dof(tet[a], c);
        if (layout.owns(dof)) own.row(dof - layout.rowStart()) -= values.row(3 * a + c);
      }
  }
  return own;
}

// Six DOFs whose pinning removes exactly the rigid motions: all of a vertex a, the two components
// of a far vertex b most perpendicular to b - a, and the component of a third vertex c along the
// normal of the plane (a, b, c). Every rank picks the same ones from the same mesh.
std::vector<PetscInt> pinnedDofs(const TetMesh& mesh, const DofLayout& layout) {
  const auto& X = mesh.vertices;
  const int a = 0;
  int b = 0, c = 0;
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if ((X[v] - X[a]).squaredNorm() > (X[b] - X[a]).squaredNorm()) b = v;
  const Eigen::Vector3d d = (X[b] - X[a]).normalized();
  auto offAxis = [&](int v) { return ((X[v] - X[a]) - (X[v] - X[a]).dot(d) * d).squaredNorm(); };
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if (offAxis(v) > offAxis(c)) c = v;
  const Eigen::Vector3d normal = d.cross(X[c] - X[a]);
  int along = 0, least = 0;
  normal.cwiseAbs().maxCoeff(&along);
  d.cwiseAbs().maxCoeff(&least);  // b's component along d cannot block rotations: skip it
  std::vector<PetscInt> dofs = {static_cast<PetscInt>(layout.dof(a, 0)), static_cast<PetscInt>(layout.dof(a, 1)),
                                static_cast<PetscInt>(layout.dof(a, 2)), static_cast<PetscInt>(layout.dof(c, along))};
  for (int k = 0; k < 3; ++k)
    if (k != least) dofs.push_back(static_cast<PetscInt>(layout.dof(b, k)));
  return dofs;
}

} // namespace

ModalDerivatives computeModalDerivatives(const TetMesh& mesh, const std::vector<Material>& perTet, Mat stiffness,
                                         Mat mass, const DofLayout& layout, const LinearModes& modes,
                                         const Eigen::MatrixXd& rigid, const DerivativeSettings& settings,
                                         StiffnessFactor* sharedFactor) {
  ModalDerivatives out;
  const int k = static_cast<int>(modes.eigenvalues.size());
  for (int i = 0; i < k; ++i)
    for (int j = i; j < k; ++j) out.pairs.push_back({i, j});

  // Right-hand sides; projected below on free objects.
  Eigen::MatrixXd b = rightHandSides(mesh, perTet, layout, layout.gatherToAll(modes.vectors));
  Eigen::MatrixXd solveFor;                    // what the (possibly pinned) system is solved for
  const bool freeObject = rigid.cols() > 0;
  PetscMat pinned;
  Mat op = stiffness;
  if (freeObject) {
    // Project b off the rigid modes (R^T b = 0 makes K x = b solvable), then pin six DOFs.
    b -= multiply(mass, rigid, layout) * innerProducts(rigid, b, layout.comm());
    const std::vector<PetscInt> pins = pinnedDofs(mesh, layout);
    solveFor = b;
    for (PetscInt row : pins)
      if (row >= layout.rowStart() && row < layout.rowStart() + layout.localDofs())
        solveFor.row(row - layout.rowStart()).setZero();
    QV_PETSC(MatDuplicate(stiffness, MAT_COPY_VALUES, pinned.out()));
    QV_PETSC(MatZeroRowsColumns(pinned, static_cast<PetscInt>(pins.size()), pins.data(), 1.0, nullptr, nullptr));
    op = pinned;
  } else {
    solveFor = b;
  }

  // A fixed object's K may already be factored (the modes at shift 0); a free one's is pinned here.
  std::unique_ptr<DirectSolver> own;
  if (freeObject || !sharedFactor) own = std::make_unique<DirectSolver>(op, layout);
  const DirectSolver& solver = own ? *own : sharedFactor->get();
  out.vectors = solver.solve(solveFor, settings.blockSize, settings.progress);
  if (freeObject) out.vectors -= rigid * innerProducts(rigid, multiply(mass, out.vectors, layout), layout.comm());

  // Normwise backward error against the unpinned system and the projected right-hand side,
  // ||K Psi - b|| / (||K||_1 ||Psi|| + ||b||): what a stable solve guarantees whatever K's
  // condition (a slender object's K reaches 1e10; ||K Psi - b|| / ||b|| then reads 1e-7 for a solve
  // as good as can be).
  const Eigen::VectorXd rn = columnNorms(multiply(stiffness, out.vectors, layout) - b, layout.comm());
  const Eigen::VectorXd bn = columnNorms(b, layout.comm());
  const Eigen::VectorXd xn = columnNorms(out.vectors, layout.comm());
  PetscReal stiffnessNorm = 0;
  QV_PETSC(MatNorm(stiffness, NORM_1, &stiffnessNorm));
  for (size_t p = 0; p < out.pairs.size(); ++p) {
    const double scale = stiffnessNorm * xn[p] + bn[p];
    out.residuals.push_back(scale > 0 ? rn[p] / scale : rn[p]);
    if (!(out.residuals.back() <= settings.maxResidual))
      throw std::runtime_error("modal derivative (" + std::to_string(out.pairs[p][0]) + ", " +
                               std::to_string(out.pairs[p][1]) + ") has relative residual " +
                               std::to_string(out.residuals.back()) + ", above the limit");
  }
  return out;
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

std::string derivativesInputHash(const std::string& modesHash) {
  return InputHash().add(modesHash).add(kDerivativesVersion).hex();
}

std::string describeDerivatives(const ModalDerivatives& derivatives) {
  return std::to_string(derivatives.pairs.size()) + " solved, max residual " +
         shortNumber(*std::max_element(derivatives.residuals.begin(), derivatives.residuals.end()));
}

ModalDerivatives derivativesStage(StageRunner& stages, const BakeContext& ctx, const TetMesh& mesh,
                                  const std::vector<Material>& perTet, const AssembledSystem& system, const DofLayout& layout, const LinearModes& modes,
                                  const Eigen::MatrixXd& rigid, StiffnessFactor& factor, const std::string& inputHash) {
  bool reused = false;
  const ModalDerivatives derivatives = stages.checkpointed(
      "derivatives", "/derivatives", inputHash, [&](const Archive& a) { return readDerivatives(a, layout); },
      [&] {
        ProgressMeter meter(ctx, "derivatives", "solved");
        DerivativeSettings settings;
        settings.progress = meter.callback();
        return computeModalDerivatives(mesh, perTet, system.stiffness, system.mass, layout, modes, rigid,
                                       settings, &factor);
      },
      [&](Archive& a, const ModalDerivatives& d, const std::string& h) { writeDerivatives(a, d, layout, h); }, reused);
  stages.report(describeDerivatives(derivatives), reused);
  return derivatives;
}

} // namespace quiver
