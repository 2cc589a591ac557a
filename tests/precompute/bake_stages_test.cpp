// The bake's stages on 1 or 2 MPI ranks against dense references computed here with Eigen from
// the common/ FEM: a generalized eigen-solve, dense solves of the derivative systems, and a dense
// mass-PCA. Every rank count must match the same references, so ranks agree with each other.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "common/box_mesh.h"
#include "common/mass_matrix.h"
#include "common/stvk_force_model.h"
#include "precompute/block_eigensolver.h"
#include "precompute/distributed_dense.h"
#include "precompute/rigid_modes.h"
#include "precompute/split_cholesky.h"
#include "precompute/stages/assemble.h"
#include "precompute/stages/basis.h"
#include "precompute/stages/modal_derivatives.h"
#include "precompute/stages/modes.h"
#include "precompute/stages/partition.h"

using namespace quiver;

namespace {

struct Problem {
  TetMesh mesh;
  std::vector<Material> perTet;
  std::vector<int> fixed;
  Partition partition;
  std::unique_ptr<DofLayout> layout;
  AssembledSystem system;
  Eigen::MatrixXd rigid;  // the bake's rigid modes on a free object, else empty
  // Dense references over the free DOFs in vertex order.
  std::vector<int> freeRows;  // rows of the full 3n system that are free
  Eigen::MatrixXd K, M;
  double extent = 0;  // ||X - c||_M from the whole mesh's consistent mass
  std::unique_ptr<StVKForceModel> model;

  // A 0.6 x 0.1 x 0.15 bar (unequal sides: no repeated eigenvalues) of 6 x 1 x 2 cells unless
  // `cells` says otherwise, two materials, clamped at x = 0 unless `free`; `scale` times as long
  // and `denser` times as dense.
  explicit Problem(bool free, const Eigen::Vector3i& cells = {6, 1, 2}, double scale = 1, double denser = 1) {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    mesh = makeBoxMesh({0.6 * scale, 0.1 * scale, 0.15 * scale}, {cells.x(), cells.y(), cells.z()});
    for (int t = 0; t < mesh.tetCount(); ++t) {
      Material m;
      m.youngsModulus = t % 3 ? 1e6 : 3e6;
      m.poissonRatio = 0.4;
      m.density = (t % 2 ? 1000 : 1300) * denser;
      perTet.push_back(m);
    }
    if (!free)
      for (int v = 0; v < mesh.vertexCount(); ++v)
        if (mesh.vertices[v].x() == 0) fixed.push_back(v);
    partition = partitionMesh(mesh, {size});
    layout = std::make_unique<DofLayout>(MPI_COMM_WORLD, partition.vertexPart, fixed);
    system = assembleSystem(mesh, perTet, *layout);
    if (free) rigid = rigidModes(mesh, system.mass, *layout);

    model = std::make_unique<StVKForceModel>(mesh, perTet);
    const Eigen::MatrixXd Kfull = model->tangentStiffness(Eigen::VectorXd::Zero(3 * mesh.vertexCount()));
    const Eigen::MatrixXd Mfull = consistentMassMatrix(mesh, perTet);
    for (int v = 0; v < mesh.vertexCount(); ++v)
      if (!std::binary_search(fixed.begin(), fixed.end(), v))
        for (int c = 0; c < 3; ++c) freeRows.push_back(3 * v + c);
    K = Kfull(freeRows, freeRows);
    M = Mfull(freeRows, freeRows);
    Eigen::VectorXd X(3 * mesh.vertexCount());
    for (int v = 0; v < mesh.vertexCount(); ++v) X.segment<3>(3 * v) = mesh.vertices[v];
    for (int a = 0; a < 3; ++a) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(X.size());
      for (int v = 0; v < mesh.vertexCount(); ++v) e(3 * v + a) = 1;
      X -= e * (e.dot(Mfull * X) / e.dot(Mfull * e));  // about the centre of mass
    }
    extent = std::sqrt(X.dot(Mfull * X));
  }

  LinearModes modes(int count) const {
    ModeSettings settings;
    settings.count = count;
    return computeLinearModes(system.stiffness, system.mass, *layout, settings, rigid);
  }
  ModalDerivatives derivatives(const LinearModes& m) const {
    return computeModalDerivatives(mesh, perTet, system.stiffness, system.mass, *layout, m, rigid,
                                   DerivativeSettings{});
  }

  // Local rows -> dense free-DOF vector(s) in vertex order, identical on every rank.
  Eigen::MatrixXd dense(const Eigen::MatrixXd& local) const { return layout->gatherToAll(local)(freeRows, Eigen::all); }
  Eigen::VectorXd fullVector(const Eigen::VectorXd& freeValues) const {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(3 * mesh.vertexCount());
    full(freeRows) = freeValues;
    return full;
  }
};

double maxRelative(const std::vector<double>& a, const Eigen::VectorXd& b) {
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]) / std::abs(b[i]));
  return worst;
}

// How far X's columns stand from span(Y): max over columns of the M-norm of x - Y Y^T M x, for
// M-orthonormal X and Y (the sine of the largest principal angle, accurate to round-off).
double subspaceGap(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, const Eigen::MatrixXd& M) {
  const Eigen::MatrixXd R = X - Y * (Y.transpose() * M * X);
  return (R.transpose() * M * R).diagonal().cwiseMax(0.0).cwiseSqrt().maxCoeff();
}

} // namespace

class BakeStages : public ::testing::TestWithParam<bool> {};

TEST_P(BakeStages, ModesMatchADenseGeneralizedEigenSolve) {
  const bool free = GetParam();
  Problem p(free);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ref(p.K, p.M);
  const int skip = free ? 6 : 0;
  for (Eigensolver solver : {Eigensolver::Block, Eigensolver::KrylovSchur}) {
    SCOPED_TRACE(eigensolverName(solver));
    ModeSettings settings;
    settings.count = 5;
    settings.solver = solver;
    LinearModes modes = computeLinearModes(p.system.stiffness, p.system.mass, *p.layout, settings, p.rigid);
    EXPECT_EQ(modes.rigidSkipped, skip);
    const Eigen::VectorXd expected = ref.eigenvalues().segment(skip, 5);
    EXPECT_LT(maxRelative(modes.eigenvalues, expected), 1e-8);
    for (double r : modes.residuals) EXPECT_LT(r, 1e-8);
    const Eigen::MatrixXd phi = p.dense(modes.vectors);
    EXPECT_LT(subspaceGap(phi, ref.eigenvectors().middleCols(skip, 5), p.M), 1e-7);
    EXPECT_LT((phi.transpose() * p.M * phi - Eigen::MatrixXd::Identity(5, 5)).cwiseAbs().maxCoeff(), 1e-10);
  }
}

// The block solver where its Krylov space closes: all but one of the elastic eigenpairs.
TEST_P(BakeStages, BlockSolverFindsAlmostEveryMode) {
  const bool free = GetParam();
  Problem p(free);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ref(p.K, p.M);
  const int skip = free ? 6 : 0, count = static_cast<int>(p.K.rows()) - skip - 1;
  ModeSettings settings;
  settings.count = count;
  LinearModes modes = computeLinearModes(p.system.stiffness, p.system.mass, *p.layout, settings, p.rigid);
  EXPECT_LT(maxRelative(modes.eigenvalues, ref.eigenvalues().segment(skip, count)), 1e-8);
  const Eigen::MatrixXd phi = p.dense(modes.vectors);
  EXPECT_LT((phi.transpose() * p.M * phi - Eigen::MatrixXd::Identity(count, count)).cwiseAbs().maxCoeff(), 1e-9);
}

// The block solver's thick restarts, forced by room for k + 4 columns (blocks of 2), on the finer
// bar: the pairs still match the dense solve.
TEST_P(BakeStages, BlockSolverRestartsAndStillMatchesTheDenseSolve) {
  const bool free = GetParam();
  Problem p(free, {16, 3, 4});
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ref(p.K, p.M);
  const int skip = free ? 6 : 0;
  // A free bar: the shift below the rigid modes' zero, as the modes stage takes it.
  const double shift = free ? -0.01 * ref.eigenvalues()[skip] : 0;
  PetscMat shifted;
  QV_PETSC(MatDuplicate(p.system.stiffness, MAT_COPY_VALUES, shifted.out()));
  QV_PETSC(MatAXPY(shifted, -shift, p.system.mass, SAME_NONZERO_PATTERN));
  const DirectSolver solver(shifted, *p.layout);
  BlockEigenSettings settings;
  settings.count = 12;
  settings.blockSize = 2;
  settings.basisColumns = settings.count + 4;
  const Eigen::MatrixXd deflation = free ? p.rigid : Eigen::MatrixXd(p.layout->localDofs(), 0);
  const BlockEigenPairs pairs = blockEigenpairs(solver, p.system.mass, shift, deflation, *p.layout, settings);
  EXPECT_GT(pairs.restarts, 0);
  EXPECT_LT(maxRelative(pairs.values, ref.eigenvalues().segment(skip, 12)), 1e-10);
  EXPECT_LT(subspaceGap(p.dense(pairs.vectors), ref.eigenvectors().middleCols(skip, 12), p.M), 1e-7);
}

// Both solvers on a finer bar (960 free DOFs).
TEST_P(BakeStages, BothSolversMatchTheDenseSolveOnAFinerBar) {
  const bool free = GetParam();
  Problem p(free, {16, 3, 4});
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ref(p.K, p.M);
  const int skip = free ? 6 : 0, count = 12;
  for (Eigensolver solver : {Eigensolver::Block, Eigensolver::KrylovSchur}) {
    SCOPED_TRACE(eigensolverName(solver));
    ModeSettings settings;
    settings.count = count;
    settings.solver = solver;
    LinearModes modes = computeLinearModes(p.system.stiffness, p.system.mass, *p.layout, settings, p.rigid);
    EXPECT_LT(maxRelative(modes.eigenvalues, ref.eigenvalues().segment(skip, count)), 1e-10);
    for (double r : modes.residuals) EXPECT_LT(r, 1e-10);
    EXPECT_LT(subspaceGap(p.dense(modes.vectors), ref.eigenvectors().middleCols(skip, count), p.M), 1e-7);
  }
}

// Every rank adds every tet touching its rows, in tet order: K and M are the serial assembly's
// bits on any rank count (and so in any run: no partial sums arrive from other ranks in message
// order). Each rank compares its rows with an assembly of its own on MPI_COMM_SELF.
TEST(BakeStages, AssembledMatricesAreTheSerialBitsOnEveryRankCount) {
  for (bool free : {false, true}) {
    Problem p(free, {8, 3, 3});
    const Partition one = partitionMesh(p.mesh, {1});
    const DofLayout serialLayout(MPI_COMM_SELF, one.vertexPart, p.fixed);
    const AssembledSystem serial = assembleSystem(p.mesh, p.perTet, serialLayout);
    std::vector<int> vertexOfRow(p.layout->globalDofs() / 3);
    for (int v = 0; v < p.mesh.vertexCount(); ++v)
      if (p.layout->dof(v, 0) >= 0) vertexOfRow[p.layout->dof(v, 0) / 3] = v;
    long compared = 0, differ = 0;
    for (const auto& [distributed, reference] :
         {std::pair{p.system.stiffness.get(), serial.stiffness.get()}, std::pair{p.system.mass.get(), serial.mass.get()}})
      for (int v : p.layout->ownedVertices())
        for (int c = 0; c < 3; ++c) {
          const PetscInt row = static_cast<PetscInt>(p.layout->dof(v, c));
          const PetscInt serialRow = static_cast<PetscInt>(serialLayout.dof(v, c));
          PetscInt n = 0;
          const PetscInt* columns = nullptr;
          const PetscScalar* values = nullptr;
          ASSERT_EQ(MatGetRow(distributed, row, &n, &columns, &values), 0);
          const PetscInt count = n;  // MatRestoreRow zeroes n
          std::vector<PetscInt> serialColumns(count);
          std::vector<PetscScalar> mine(values, values + count), theirs(count);
          for (PetscInt i = 0; i < count; ++i)
            serialColumns[i] = static_cast<PetscInt>(serialLayout.dof(vertexOfRow[columns[i] / 3], columns[i] % 3));
          ASSERT_EQ(MatRestoreRow(distributed, row, &n, &columns, &values), 0);
          PetscInt serialCount = 0;
          ASSERT_EQ(MatGetRow(reference, serialRow, &serialCount, nullptr, nullptr), 0);
          differ += serialCount != count;  // no entry missing from the distributed row
          ASSERT_EQ(MatRestoreRow(reference, serialRow, &serialCount, nullptr, nullptr), 0);
          ASSERT_EQ(MatGetValues(reference, 1, &serialRow, count, serialColumns.data(), theirs.data()), 0);
          for (PetscInt i = 0; i < count; ++i) differ += mine[i] != theirs[i];
          compared += count;
        }
    EXPECT_EQ(differ, 0) << "of " << compared << " entries, free " << free;
    EXPECT_GT(compared, 0);
  }
}

// A fixed object's derivatives through the modes' factor of K are the ones a factor of their own gives.
TEST(BakeStages, DerivativesThroughTheSharedFactorAreTheSame) {
  Problem p(false);
  StiffnessFactor shared(p.system.stiffness, *p.layout);
  ModeSettings settings;
  settings.count = 3;
  const LinearModes modes = computeLinearModes(p.system.stiffness, p.system.mass, *p.layout, settings, p.rigid, &shared);
  const ModalDerivatives own = p.derivatives(modes);
  const ModalDerivatives reused = computeModalDerivatives(p.mesh, p.perTet, p.system.stiffness,
                                                          p.system.mass, *p.layout, modes, p.rigid, DerivativeSettings{},
                                                          &shared);
  EXPECT_EQ((own.vectors - reused.vectors).cwiseAbs().maxCoeff(), 0.0);
}

// -factor_distributed (PETSc's parallel MUMPS instead of our factors) solves the same
// systems: its modes and its derivatives of the same modes agree with the default's to round-off.
TEST(BakeStages, DistributedFactorSolvesTheSameSystems) {
  Problem p(false);
  const LinearModes modes = p.modes(3);
  const ModalDerivatives d = p.derivatives(modes);
  // PETSc's numeric Cholesky runs only on that path: count its calls.
  QV_PETSC(PetscLogDefaultBegin());
  PetscLogEvent numeric = 0;
  QV_PETSC(PetscLogEventGetId("MatCholFctrNum", &numeric));
  auto factorizations = [&] {
    PetscEventPerfInfo info{};
    QV_PETSC(PetscLogEventGetPerfInfo(0, numeric, &info));
    return info.count;
  };
  const int before = factorizations();
  QV_PETSC(PetscOptionsSetValue(nullptr, "-factor_distributed", "1"));
  LinearModes otherModes;
  ModalDerivatives other;
  EXPECT_NO_THROW({
    otherModes = p.modes(3);
    other = p.derivatives(modes);
  });
  QV_PETSC(PetscOptionsClearValue(nullptr, "-factor_distributed"));
  EXPECT_EQ(factorizations() - before, 2);  // K for the modes, K again for the derivatives
  ASSERT_EQ(otherModes.eigenvalues.size(), 3u);
  EXPECT_LT(maxRelative(otherModes.eigenvalues, Eigen::Map<const Eigen::VectorXd>(modes.eigenvalues.data(), 3)), 1e-10);
  EXPECT_LT(subspaceGap(p.dense(otherModes.vectors), p.dense(modes.vectors), p.M), 1e-7);
  const Eigen::MatrixXd psi = p.dense(d.vectors);
  EXPECT_LT((p.dense(other.vectors) - psi).norm(), 1e-10 * psi.norm());
}

// The factor split by rank (a Schur complement on the interface) solves like a dense factor; on
// one rank, or with no room for an interface, there is no split.
TEST(BakeStages, SplitFactorSolvesLikeADenseFactor) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  Problem p(false, {16, 3, 4});
  const auto split = SplitCholesky::tryCreate(p.system.stiffness, MPI_COMM_WORLD, 100000);
  EXPECT_EQ(split == nullptr, size == 1);
  EXPECT_EQ(SplitCholesky::tryCreate(p.system.stiffness, MPI_COMM_WORLD, 0), nullptr);
  if (!split) return;
  EXPECT_GT(split->interfaceRows(), 0);
  const Eigen::Index n = p.layout->localDofs();
  Eigen::MatrixXd B(n, 3), X(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) B(i, c) = std::sin(1.0 + 0.37 * (p.layout->rowStart() + i) + c);
  split->solve(B.data(), X.data(), 3);
  const Eigen::MatrixXd expected = p.K.ldlt().solve(p.dense(B));
  EXPECT_LT((p.dense(X) - expected).norm(), 1e-10 * expected.norm());
}

// With no room for an interface (-factor_max_interface 0) every rank factors the whole matrix and
// solves its share of the columns: the same solutions as a dense factor.
TEST(BakeStages, WholeFactorPerRankSolvesLikeADenseFactor) {
  Problem p(false, {16, 3, 4});
  QV_PETSC(PetscOptionsSetValue(nullptr, "-factor_max_interface", "0"));
  std::unique_ptr<DirectSolver> solver;
  EXPECT_NO_THROW(solver = std::make_unique<DirectSolver>(p.system.stiffness, *p.layout));
  QV_PETSC(PetscOptionsClearValue(nullptr, "-factor_max_interface"));
  ASSERT_TRUE(solver);
  const Eigen::Index n = p.layout->localDofs();
  Eigen::MatrixXd B(n, 5);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < 5; ++c) B(i, c) = std::cos(0.3 + 0.11 * (p.layout->rowStart() + i) * (c + 1));
  const Eigen::MatrixXd X = solver->solve(B, 2);  // rounds of 2 columns: ranks own uneven shares
  const Eigen::MatrixXd expected = p.K.ldlt().solve(p.dense(B));
  EXPECT_LT((p.dense(X) - expected).norm(), 1e-10 * expected.norm());
}

// -factor_max_interface outside 0..46340 (the dense Schur complement's MPI counts) is refused on
// every rank, naming the option.
TEST(BakeStages, MaxInterfaceOutOfRangeIsRefused) {
  Problem p(false);
  for (const char* value : {"-1", "46341"}) {
    QV_PETSC(PetscOptionsSetValue(nullptr, "-factor_max_interface", value));
    try {
      DirectSolver solver(p.system.stiffness, *p.layout);
      ADD_FAILURE() << value << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("-factor_max_interface ") + value + ": must lie in 0..46340"),
                std::string::npos) << e.what();
    }
    QV_PETSC(PetscOptionsClearValue(nullptr, "-factor_max_interface"));
  }
}

TEST_P(BakeStages, DerivativesSolveTheDenseSystem) {
  const bool free = GetParam();
  Problem p(free);
  const LinearModes modes = p.modes(3);
  const ModalDerivatives d = p.derivatives(modes);
  ASSERT_EQ(d.pairs.size(), 6u);
  for (double r : d.residuals) EXPECT_LT(r, 1e-8);
  const Eigen::MatrixXd phi = p.dense(modes.vectors), psi = p.dense(d.vectors);
  // Reference: -K^+ d^2R[phi_i, phi_j] from the full-space model, M-orthogonal to rigid motions.
  // Rigid motions built here from the vertex positions (translations, infinitesimal rotations).
  Eigen::MatrixXd rigid(3 * p.mesh.vertexCount(), 6);
  for (int v = 0; v < p.mesh.vertexCount(); ++v) {
    const Eigen::Vector3d x = p.mesh.vertices[v];
    rigid.block<3, 3>(3 * v, 0).setIdentity();
    for (int a = 0; a < 3; ++a) rigid.block<3, 1>(3 * v, 3 + a) = Eigen::Vector3d::Unit(a).cross(x);
  }
  if (free) {
    Eigen::LLT<Eigen::MatrixXd> gram(rigid.transpose() * p.M * rigid);
    rigid = gram.matrixU().solve<Eigen::OnTheRight>(rigid);  // R U^{-1}: M-orthonormal
    EXPECT_LT((rigid.transpose() * p.M * rigid - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LT(subspaceGap(rigid, p.dense(p.rigid), p.M), 1e-10);
  }
  for (size_t q = 0; q < d.pairs.size(); ++q) {
    Eigen::VectorXd h;
    p.model->forceHessianAtRest(p.fullVector(phi.col(d.pairs[q][0])), p.fullVector(phi.col(d.pairs[q][1])), h);
    Eigen::VectorXd b = -h(p.freeRows);
    Eigen::VectorXd x;
    if (free) {
      b -= p.M * rigid * (rigid.transpose() * b);
      x = p.K.completeOrthogonalDecomposition().solve(b);
      x -= rigid * (rigid.transpose() * p.M * x);
    } else {
      x = p.K.ldlt().solve(b);
    }
    EXPECT_LT((psi.col(q) - x).norm(), 1e-8 * x.norm()) << "pair " << d.pairs[q][0] << "," << d.pairs[q][1];
  }
}

TEST_P(BakeStages, BasisIsTheDenseMassPcaAndMassOrthonormal) {
  const bool free = GetParam();
  Problem p(free);
  const LinearModes modes = p.modes(3);
  const ModalDerivatives d = p.derivatives(modes);
  BasisSettings bs;
  bs.rank = 5;
  bs.pcaAmplitude = 0.7;
  EXPECT_NEAR(objectExtent(p.mesh, p.perTet), p.extent, 1e-12 * p.extent);
  ReducedBasis basis = buildBasis(p.system.mass, *p.layout, modes, d, p.extent, bs);
  const Eigen::MatrixXd U = p.dense(basis.vectors);
  EXPECT_LT((U.transpose() * p.M * U - Eigen::MatrixXd::Identity(5, 5)).cwiseAbs().maxCoeff(), 1e-10);

  // Dense mass-PCA of the same scaled set: with M = L L^T, the SVD of L^T A.
  const Eigen::MatrixXd phi = p.dense(modes.vectors), psi = p.dense(d.vectors);
  const double l1 = modes.eigenvalues[0];
  Eigen::MatrixXd A(phi.rows(), 9);
  for (int i = 0; i < 3; ++i) A.col(i) = phi.col(i) * l1 / modes.eigenvalues[i];
  for (int q = 0; q < 6; ++q) {
    const int i = d.pairs[q][0], j = d.pairs[q][1];
    A.col(3 + q) = psi.col(q) * 0.7 * p.extent * (i == j ? 1.0 : std::sqrt(2.0)) * l1 * l1 /
                   (modes.eigenvalues[i] * modes.eigenvalues[j]);
  }
  Eigen::LLT<Eigen::MatrixXd> llt(p.M);
  Eigen::MatrixXd LtA = llt.matrixU() * A;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(LtA, Eigen::ComputeThinU);
  const Eigen::MatrixXd Uref = llt.matrixU().solve(svd.matrixU().leftCols(5));
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(basis.singularValues[i], svd.singularValues()[i], 1e-9 * svd.singularValues()[0]);
  EXPECT_LT(subspaceGap(U, Uref, p.M), 1e-7);
}

// The same shape 7 times as long and 40 times as dense, in the units an artist's file might use,
// must get the same basis: only the mass norm changes, by sqrt(40 * 7^3), not the directions.
TEST_P(BakeStages, PcaBasisIsTheSameWhateverTheSizeAndDensity) {
  const bool free = GetParam();
  const double scale = 7, denser = 40;
  Problem a(free), b(free, {6, 1, 2}, scale, denser);
  BasisSettings bs;
  bs.rank = 5;
  const LinearModes ma = a.modes(3), mb = b.modes(3);
  const Eigen::MatrixXd Ua = a.dense(buildBasis(a.system.mass, *a.layout, ma, a.derivatives(ma), a.extent, bs).vectors);
  const Eigen::MatrixXd Ub = b.dense(buildBasis(b.system.mass, *b.layout, mb, b.derivatives(mb), b.extent, bs).vectors);
  EXPECT_LT(subspaceGap(Ua, Ub * std::sqrt(denser * scale * scale * scale), a.M), 1e-7);
}

// --resume reuses the polynomials (the costly stage) by this hash: the amplitude counts where the
// recipe uses it, and only there.
TEST(BakeStages, OnlyThePcaRecipeHashesItsAmplitude) {
  BasisSettings a, b;
  b.pcaAmplitude = 0.5;
  EXPECT_NE(basisInputHash("derivatives", a), basisInputHash("derivatives", b));
  for (BasisKind kind : {BasisKind::KeepModes, BasisKind::Modes}) {
    a.kind = b.kind = kind;
    EXPECT_EQ(basisInputHash("derivatives", a), basisInputHash("derivatives", b)) << basisKindName(kind);
  }
}

TEST(BakeStages, UserBasisIsMassOrthonormalisedAndFlagged) {
  Problem p(false);
  Eigen::MatrixXd raw = Eigen::MatrixXd::Zero(p.layout->localDofs(), 2);
  raw.col(0).setConstant(1.0);
  for (int i = 0; i < raw.rows(); ++i) raw(i, 1) = (i % 3) + 0.5;
  bool wasOrthonormal = true;
  ReducedBasis b = importBasis(p.system.mass, *p.layout, raw, wasOrthonormal);
  EXPECT_FALSE(wasOrthonormal);
  const Eigen::MatrixXd U = p.dense(b.vectors);
  EXPECT_LT((U.transpose() * p.M * U - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff(), 1e-10);
  raw.col(1) = 2 * raw.col(0);
  EXPECT_THROW(importBasis(p.system.mass, *p.layout, raw, wasOrthonormal), std::runtime_error);
}

INSTANTIATE_TEST_SUITE_P(FixedAndFree, BakeStages, ::testing::Values(false, true),
                         [](const auto& param) { return param.param ? "free" : "clamped"; });
