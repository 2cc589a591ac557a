#include "precompute/stages/modal_derivatives.h"

#include <algorithm>
#include <climits>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <petscksp.h>

#include "common/stvk_element.h"
#include "precompute/checkpoint.h"
#include "precompute/input_hash.h"
#include "precompute/distributed_dense.h"

namespace quiver {

namespace {

using PetscKsp = PetscHandle<KSP, KSPDestroy>;

// -d^2R[phi_i, phi_j] for every pair, as a distributed dense matrix (free DOFs x pairs).
PetscMat rightHandSides(const TetMesh& mesh, const std::vector<Material>& perTet, const std::vector<int>& tetPart,
                        const DofLayout& layout, const Eigen::MatrixXd& fullModes,
                        const std::vector<std::array<int, 2>>& pairs) {
  int rank = 0;
  MPI_Comm_rank(layout.comm(), &rank);
  const PetscInt P = static_cast<PetscInt>(pairs.size());
  PetscMat B;
  QV_PETSC(MatCreateDense(layout.comm(), layout.localDofs(), PETSC_DECIDE, layout.globalDofs(), P, nullptr, B.out()));
  QV_PETSC(MatZeroEntries(B));
  const TetElements elements = computeTetElements(mesh);
  std::vector<PetscInt> columns(P);
  for (PetscInt p = 0; p < P; ++p) columns[p] = p;
  std::vector<RestDirection> modeOnTet(fullModes.cols());
  Eigen::Matrix<double, 12, Eigen::Dynamic, Eigen::RowMajor> values(12, P);
  PetscInt dofs[12];
  for (int t = 0; t < mesh.tetCount(); ++t) {
    if (tetPart[t] != rank) continue;
    const Tet& tet = mesh.tets[t];
    const Material& m = perTet[t];
    for (int i = 0; i < fullModes.cols(); ++i) {  // each mode's H and delta S once per tet, not per pair
      Matrix34 onTet;
      for (int a = 0; a < 4; ++a) onTet.col(a) = fullModes.block<3, 1>(3 * tet[a], i);
      modeOnTet[i] = stvkRestDirection(onTet, elements.gradients[t], m.lambda(), m.mu());
    }
    for (PetscInt p = 0; p < P; ++p) {
      const Matrix34 f = stvkElementForceHessianAtRest(modeOnTet[pairs[p][0]], modeOnTet[pairs[p][1]],
                                                       elements.gradients[t], elements.volume[t], m.lambda(), m.mu());
      values.col(p) = -Eigen::Map<const Eigen::Matrix<double, 12, 1>>(f.data());
    }
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) dofs[3 * a + c] = static_cast<PetscInt>(layout.dof(tet[a], c));
    QV_PETSC(MatSetValues(B, 12, dofs, P, columns.data(), values.data(), ADD_VALUES));
  }
  QV_PETSC(MatAssemblyBegin(B, MAT_FINAL_ASSEMBLY));
  QV_PETSC(MatAssemblyEnd(B, MAT_FINAL_ASSEMBLY));
  return B;
}

Eigen::MatrixXd localBlock(Mat dense, const DofLayout& layout) {
  PetscInt lda = 0, cols = 0;
  const PetscScalar* values = nullptr;
  QV_PETSC(MatGetSize(dense, nullptr, &cols));
  QV_PETSC(MatDenseGetLDA(dense, &lda));
  QV_PETSC(MatDenseGetArrayRead(dense, &values));
  Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>(values, layout.localDofs(), cols,
                                                                                  Eigen::OuterStride<>(lda));
  QV_PETSC(MatDenseRestoreArrayRead(dense, &values));
  return out;
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

// A Cholesky solver of A (MUMPS; -derivatives_* options) on A's communicator.
PetscKsp choleskySolver(Mat A) {
  PetscKsp ksp;
  PC pc;
  QV_PETSC(KSPCreate(PetscObjectComm(reinterpret_cast<PetscObject>(A)), ksp.out()));
  QV_PETSC(KSPSetOptionsPrefix(ksp, "derivatives_"));
  QV_PETSC(KSPSetOperators(ksp, A, A));
  QV_PETSC(KSPSetType(ksp, KSPPREONLY));
  QV_PETSC(KSPGetPC(ksp, &pc));
  QV_PETSC(PCSetType(pc, PCCHOLESKY));
  QV_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  QV_PETSC(KSPSetFromOptions(ksp));
  return ksp;
}

// MPI_Alltoallv of doubles; the counts (per rank) must fit MPI's int, which solveColumns' rounds do.
std::vector<double> exchange(const std::vector<double>& send, const std::vector<size_t>& sendCounts,
                             const std::vector<size_t>& receiveCounts, MPI_Comm comm) {
  const size_t size = sendCounts.size();
  std::vector<int> sc(size), so(size), rc(size), ro(size);
  size_t sent = 0, received = 0;
  for (size_t p = 0; p < size; ++p) {
    if (sent + sendCounts[p] > INT_MAX || received + receiveCounts[p] > INT_MAX)
      throw std::runtime_error("modal derivatives: a block of right-hand sides is too large for one MPI exchange");
    so[p] = static_cast<int>(sent);
    sc[p] = static_cast<int>(sendCounts[p]);
    ro[p] = static_cast<int>(received);
    rc[p] = static_cast<int>(receiveCounts[p]);
    sent += sendCounts[p];
    received += receiveCounts[p];
  }
  std::vector<double> receive(received);
  MPI_Alltoallv(send.data(), sc.data(), so.data(), MPI_DOUBLE, receive.data(), rc.data(), ro.data(), MPI_DOUBLE, comm);
  return receive;
}

// K X = B (B and X this rank's rows), in rounds of settings.blockSize right-hand sides.
//
// On one rank, one factorization of the distributed K. On several, parallel MUMPS would give bits
// that change from run to run (it schedules its work as messages arrive), and SuperLU_DIST's
// multi-right-hand-side solve corrupts its heap in Debian 12 (pdReDistribute_B_to_X). So every
// rank factors the whole of K alone and solves its own share of the columns, whose bits depend on
// the inputs and the rank count only (issue #16). The cost is a copy of K and its factor per rank;
// -derivatives_distributed goes back to one distributed factorization (less memory per rank).
Eigen::MatrixXd solveColumns(Mat op, Eigen::MatrixXd B, const DofLayout& layout, const DerivativeSettings& settings) {
  int rank = 0, size = 1;
  MPI_Comm_rank(layout.comm(), &rank);
  MPI_Comm_size(layout.comm(), &size);
  PetscBool distributed = PETSC_FALSE;
  QV_PETSC(PetscOptionsGetBool(nullptr, "derivatives_", "-distributed", &distributed, nullptr));
  const Eigen::Index total = B.cols(), block = settings.blockSize;
  Eigen::MatrixXd X(B.rows(), total);
  if (size == 1 || distributed) {
    PetscKsp ksp = choleskySolver(op);
    for (Eigen::Index first = 0; first < total; first += block) {
      const Eigen::Index count = std::min(block, total - first);
      PetscMat b = wrapDenseColumns(B, first, count, layout), x = wrapDenseColumns(X, first, count, layout);
      QV_PETSC(KSPMatSolve(ksp, b, x));
      if (settings.progress) settings.progress(first + count, total);
    }
    return X;
  }

  PetscMat whole;  // this rank's own copy of the whole matrix, on a communicator of one
  QV_PETSC(MatCreateRedundantMatrix(op, size, MPI_COMM_NULL, MAT_INITIAL_MATRIX, whole.out()));
  PetscKsp ksp = choleskySolver(whole);
  const MPI_Comm self = PetscObjectComm(reinterpret_cast<PetscObject>(static_cast<Mat>(whole)));
  const PetscInt* ranges = nullptr;  // rows follow PETSc's ownership ranges
  QV_PETSC(MatGetOwnershipRanges(op, &ranges));
  auto rows = [&](int p) { return static_cast<Eigen::Index>(ranges[p + 1] - ranges[p]); };
  auto start = [&](int p) { return total * p / size; };  // rank p's columns: [start(p), start(p + 1))
  Eigen::Index most = 0, widest = 0;
  for (int p = 0; p < size; ++p) {
    most = std::max(most, start(p + 1) - start(p));
    widest = std::max(widest, rows(p));
  }
  const Eigen::Index n = layout.globalDofs();
  // Rounds small enough that every exchange's counts fit MPI's int (the same on every rank).
  const Eigen::Index round =
      std::max<Eigen::Index>(1, std::min<Eigen::Index>(block, INT_MAX / std::max(n, widest * size)));
  for (Eigen::Index first = 0; first < most; first += round) {
    // This round: columns [begin(p), begin(p) + count(p)) of each rank p.
    auto begin = [&](int p) { return start(p) + first; };
    auto count = [&](int p) { return std::clamp<Eigen::Index>(start(p + 1) - begin(p), 0, round); };
    const Eigen::Index mine = count(rank);
    // Each rank's rows of my columns, in global row order.
    std::vector<double> send;
    std::vector<size_t> sendCounts(size), receiveCounts(size);
    for (int p = 0; p < size; ++p) {
      if (count(p) > 0) {  // columns of one rank are contiguous in B
        const double* part = B.col(begin(p)).data();
        send.insert(send.end(), part, part + B.rows() * count(p));
      }
      sendCounts[p] = static_cast<size_t>(B.rows() * count(p));
      receiveCounts[p] = static_cast<size_t>(rows(p) * mine);
    }
    std::vector<double> received = exchange(send, sendCounts, receiveCounts, layout.comm());
    Eigen::MatrixXd rhs(n, mine), x(n, mine);
    for (int p = 0, offset = 0; p < size; offset += static_cast<int>(receiveCounts[p]), ++p)
      rhs.middleRows(ranges[p], rows(p)) = Eigen::Map<const Eigen::MatrixXd>(received.data() + offset, rows(p), mine);
    // A rank's own solve may fail alone (memory, MUMPS): every rank learns it before the next
    // exchange, or the others would wait there for ever.
    std::string failure;
    if (mine > 0) {
      try {
        PetscMat b, solution;
        QV_PETSC(MatCreateSeqDense(self, n, mine, rhs.data(), b.out()));
        QV_PETSC(MatCreateSeqDense(self, n, mine, x.data(), solution.out()));
        QV_PETSC(KSPMatSolve(ksp, b, solution));
      } catch (const std::exception& e) {
        failure = e.what();
      }
    }
    int failed = failure.empty() ? 0 : 1, anyFailed = 0;
    MPI_Allreduce(&failed, &anyFailed, 1, MPI_INT, MPI_MAX, layout.comm());
    if (anyFailed)
      throw std::runtime_error("modal derivatives: " +
                               (failure.empty() ? std::string("another rank's solve failed") : failure));
    // And back: each rank gets its rows of my columns.
    send.clear();
    for (int p = 0; p < size; ++p) {
      const Eigen::MatrixXd part = x.middleRows(ranges[p], rows(p));
      send.insert(send.end(), part.data(), part.data() + part.size());
      sendCounts[p] = static_cast<size_t>(part.size());
      receiveCounts[p] = static_cast<size_t>(B.rows() * count(p));
    }
    received = exchange(send, sendCounts, receiveCounts, layout.comm());
    for (int p = 0, offset = 0; p < size; offset += static_cast<int>(receiveCounts[p]), ++p)
      if (count(p) > 0)
        X.middleCols(begin(p), count(p)) = Eigen::Map<const Eigen::MatrixXd>(received.data() + offset, B.rows(), count(p));
    if (settings.progress) {
      Eigen::Index solved = 0;
      for (int p = 0; p < size; ++p) solved += std::min(start(p + 1) - start(p), first + round);
      settings.progress(solved, total);
    }
  }
  return X;
}

} // namespace

ModalDerivatives computeModalDerivatives(const TetMesh& mesh, const std::vector<Material>& perTet,
                                         const std::vector<int>& tetPart, Mat stiffness, Mat mass,
                                         const DofLayout& layout, const LinearModes& modes,
                                         const Eigen::MatrixXd& rigid, const DerivativeSettings& settings) {
  ModalDerivatives out;
  const int k = static_cast<int>(modes.eigenvalues.size());
  for (int i = 0; i < k; ++i)
    for (int j = i; j < k; ++j) out.pairs.push_back({i, j});

  PetscMat B = rightHandSides(mesh, perTet, tetPart, layout, layout.gatherToAll(modes.vectors), out.pairs);
  Eigen::MatrixXd b = localBlock(B, layout);  // right-hand sides; projected below on free objects
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

  out.vectors = solveColumns(op, std::move(solveFor), layout, settings);
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
                                  const std::vector<Material>& perTet, const std::vector<int>& tetPart,
                                  const AssembledSystem& system, const DofLayout& layout, const LinearModes& modes,
                                  const Eigen::MatrixXd& rigid, const std::string& inputHash) {
  bool reused = false;
  const ModalDerivatives derivatives = stages.checkpointed(
      "derivatives", "/derivatives", inputHash, [&](const Archive& a) { return readDerivatives(a, layout); },
      [&] {
        ProgressMeter meter(ctx, "derivatives", "solved");
        DerivativeSettings settings;
        settings.progress = meter.callback();
        return computeModalDerivatives(mesh, perTet, tetPart, system.stiffness, system.mass, layout, modes, rigid,
                                       settings);
      },
      [&](Archive& a, const ModalDerivatives& d, const std::string& h) { writeDerivatives(a, d, layout, h); }, reused);
  stages.report(describeDerivatives(derivatives), reused);
  return derivatives;
}

} // namespace quiver
