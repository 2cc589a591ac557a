#include "precompute/stages/modes.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include <dlfcn.h>
#include <slepceps.h>

#include "precompute/block_eigensolver.h"
#include "precompute/checkpoint.h"
#include "precompute/input_hash.h"
#include "precompute/distributed_dense.h"

namespace quiver {

namespace {

using PetscEps = PetscHandle<EPS, EPSDestroy>;
using PetscVec = PetscHandle<Vec, VecDestroy>;

struct EigenPairs {
  std::vector<double> values;  // ascending
  Eigen::MatrixXd vectors;     // this rank's rows
};

struct MonitorContext {
  const ProgressCallback* progress;
  int wanted;
};

// SLEPc monitor: passes the number of converged pairs on to the stage's progress callback.
PetscErrorCode reportConverged(EPS, PetscInt, PetscInt converged, PetscScalar*, PetscScalar*, PetscReal*, PetscInt,
                               void* context) {
  const auto* c = static_cast<const MonitorContext*>(context);
  (*c->progress)(converged, c->wanted);
  return 0;
}

// The `count` eigenpairs nearest `shift` by SLEPc's Krylov-Schur with shift-and-invert (a direct
// solver), M-orthogonal to `deflation`'s columns. `fromOptions` lets -eps_* / -st_* override the defaults.
EigenPairs slepcKrylovSchur(Mat stiffness, Mat mass, const DofLayout& layout, double shift, int count, double tolerance,
                            const Eigen::MatrixXd& deflation, bool fromOptions, const ProgressCallback& progress) {
  PetscEps eps;
  QV_PETSC(EPSCreate(layout.comm(), eps.out()));
  QV_PETSC(EPSSetOperators(eps, stiffness, mass));
  QV_PETSC(EPSSetProblemType(eps, EPS_GHEP));
  QV_PETSC(EPSSetType(eps, EPSKRYLOVSCHUR));
  QV_PETSC(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  QV_PETSC(EPSSetTarget(eps, shift));
  QV_PETSC(EPSSetDimensions(eps, count, PETSC_DEFAULT, PETSC_DEFAULT));
  QV_PETSC(EPSSetTolerances(eps, tolerance, 1000));
  ST st;
  KSP ksp;
  PC pc;
  QV_PETSC(EPSGetST(eps, &st));
  QV_PETSC(STSetType(st, STSINVERT));
  QV_PETSC(STGetKSP(st, &ksp));
  QV_PETSC(KSPSetType(ksp, KSPPREONLY));
  QV_PETSC(KSPGetPC(ksp, &pc));
  int ranks = 1;
  MPI_Comm_size(layout.comm(), &ranks);
  // The same bits every run (issue #16). Parallel MUMPS schedules its work as messages arrive, so its
  // solves differ in the last bits from run to run. SuperLU_DIST's triangular solves receive from
  // any rank in turn, which fixes the order of their sums only when there is one other rank; and
  // they sum per-thread partial results, so one OpenMP thread per rank (a bake runs a rank per core
  // anyway; OpenMP is SuperLU_DIST's, not ours). On more ranks every rank factors the whole of K
  // alone (PCREDUNDANT), as the derivatives do.
  if (ranks == 1) {
    QV_PETSC(PCSetType(pc, PCCHOLESKY));
    QV_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  } else if (ranks == 2) {
    if (auto* setThreads = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "omp_set_num_threads")))
      setThreads(1);
    QV_PETSC(PCSetType(pc, PCLU));
    QV_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERSUPERLU_DIST));
  } else {
    KSP whole;
    PC factor;
    QV_PETSC(PCSetType(pc, PCREDUNDANT));
    QV_PETSC(PCRedundantSetNumber(pc, ranks));
    QV_PETSC(PCRedundantGetKSP(pc, &whole));
    QV_PETSC(KSPGetPC(whole, &factor));
    QV_PETSC(PCSetType(factor, PCCHOLESKY));
    QV_PETSC(PCFactorSetMatSolverType(factor, MATSOLVERMUMPS));
  }
  std::vector<PetscVec> deflationVecs(deflation.cols());
  std::vector<Vec> raw;
  for (Eigen::Index j = 0; j < deflation.cols(); ++j) {
    QV_PETSC(MatCreateVecs(stiffness, deflationVecs[j].out(), nullptr));
    PetscScalar* values;
    QV_PETSC(VecGetArray(deflationVecs[j], &values));
    Eigen::Map<Eigen::VectorXd>(values, layout.localDofs()) = deflation.col(j);
    QV_PETSC(VecRestoreArray(deflationVecs[j], &values));
    raw.push_back(deflationVecs[j]);
  }
  if (!raw.empty()) QV_PETSC(EPSSetDeflationSpace(eps, static_cast<PetscInt>(raw.size()), raw.data()));
  MonitorContext monitor{&progress, count};
  if (progress) QV_PETSC(EPSMonitorSet(eps, reportConverged, &monitor, nullptr));
  if (fromOptions) QV_PETSC(EPSSetFromOptions(eps));
  QV_PETSC(EPSSolve(eps));

  PetscInt converged = 0;
  QV_PETSC(EPSGetConverged(eps, &converged));
  if (converged < count) {
    EPSConvergedReason reason;
    QV_PETSC(EPSGetConvergedReason(eps, &reason));
    std::ostringstream why;
    why << "SLEPc found " << converged << " of the " << count << " eigenpairs requested (" << EPSConvergedReasons[reason]
        << "); try a larger -eps_max_it or -eps_ncv";
    throw std::runtime_error(why.str());
  }
  std::vector<double> lambda(converged);
  for (PetscInt i = 0; i < converged; ++i) {
    PetscScalar re, im;
    QV_PETSC(EPSGetEigenvalue(eps, i, &re, &im));
    lambda[i] = re;
  }
  std::vector<int> order(converged);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return lambda[a] < lambda[b]; });
  EigenPairs out;
  out.vectors.resize(layout.localDofs(), count);
  PetscVec x;
  QV_PETSC(MatCreateVecs(stiffness, x.out(), nullptr));
  for (int j = 0; j < count; ++j) {
    out.values.push_back(lambda[order[j]]);
    QV_PETSC(EPSGetEigenvector(eps, order[j], x, nullptr));
    const PetscScalar* values;
    QV_PETSC(VecGetArrayRead(x, &values));
    out.vectors.col(j) = Eigen::Map<const Eigen::VectorXd>(values, layout.localDofs());
    QV_PETSC(VecRestoreArrayRead(x, &values));
  }
  return out;
}

// The `count` eigenpairs nearest `shift` (below them all) by the block solver, with a factor of
// K - shift M: K's shared one at shift 0.
EigenPairs blockKrylovSchur(Mat stiffness, Mat mass, const DofLayout& layout, double shift, int count,
                            double tolerance, const Eigen::MatrixXd& deflation, StiffnessFactor* sharedFactor,
                            const ProgressCallback& progress) {
  std::unique_ptr<DirectSolver> own;
  PetscMat shifted;
  if (shift != 0) {
    QV_PETSC(MatDuplicate(stiffness, MAT_COPY_VALUES, shifted.out()));
    QV_PETSC(MatAXPY(shifted, -shift, mass, UNKNOWN_NONZERO_PATTERN));
    own = std::make_unique<DirectSolver>(shifted, layout);
  } else if (!sharedFactor) {
    own = std::make_unique<DirectSolver>(stiffness, layout);
  }
  const DirectSolver& solver = own ? *own : sharedFactor->get();
  BlockEigenSettings settings;
  settings.count = count;
  settings.tolerance = tolerance;
  settings.progress = progress;
  PetscInt blockSize = 0;  // -modes_block_size: columns per block (default: block_eigensolver.h)
  QV_PETSC(PetscOptionsGetInt(nullptr, nullptr, "-modes_block_size", &blockSize, nullptr));
  settings.blockSize = static_cast<int>(blockSize);
  BlockEigenPairs pairs = blockEigenpairs(solver, mass, shift, deflation, layout, settings);
  return {std::move(pairs.values), std::move(pairs.vectors)};
}

// Largest diagonal ratio K_ii / M_ii: the scale of the pencil's eigenvalues.
double diagonalRatio(Mat stiffness, Mat mass) {
  PetscVec k, m;
  QV_PETSC(MatCreateVecs(stiffness, k.out(), nullptr));
  QV_PETSC(MatCreateVecs(mass, m.out(), nullptr));
  QV_PETSC(MatGetDiagonal(stiffness, k));
  QV_PETSC(MatGetDiagonal(mass, m));
  QV_PETSC(VecPointwiseDivide(k, k, m));
  PetscReal ratio = 0;
  QV_PETSC(VecMax(k, nullptr, &ratio));
  return ratio;
}

} // namespace

std::vector<double> LinearModes::frequenciesHz() const {
  std::vector<double> f;
  for (double lambda : eigenvalues) f.push_back(std::sqrt(std::max(lambda, 0.0)) / (2 * M_PI));
  return f;
}

std::vector<double> eigenResiduals(Mat stiffness, Mat mass, const std::vector<double>& eigenvalues,
                                   const Eigen::MatrixXd& vectors, const DofLayout& layout) {
  PetscReal normK = 0;
  QV_PETSC(MatNorm(stiffness, NORM_1, &normK));
  Eigen::MatrixXd r = multiply(stiffness, vectors, layout) -
                      multiply(mass, vectors, layout) * Eigen::Map<const Eigen::VectorXd>(eigenvalues.data(), eigenvalues.size()).asDiagonal();
  const Eigen::VectorXd rn = columnNorms(r, layout.comm()), xn = columnNorms(vectors, layout.comm());
  std::vector<double> out;
  for (int j = 0; j < rn.size(); ++j) out.push_back(rn[j] / (normK * xn[j]));
  return out;
}

LinearModes computeLinearModes(Mat stiffness, Mat mass, const DofLayout& layout, const ModeSettings& settings,
                               const Eigen::MatrixXd& rigid, StiffnessFactor* sharedFactor) {
  const int64_t available = layout.globalDofs() - rigid.cols();
  if (settings.count >= available)
    throw std::runtime_error("cannot compute " + std::to_string(settings.count) + " modes of a system with " +
                             std::to_string(available) + " elastic degrees of freedom");
  // `wanted`: the solve that gives the modes (it reports progress; SLEPc's options apply to it).
  auto solve = [&](double shift, int count, double tolerance, bool wanted) {
    const ProgressCallback progress = wanted ? settings.progress : ProgressCallback();
    return settings.solver == Eigensolver::Block
               ? blockKrylovSchur(stiffness, mass, layout, shift, count, tolerance, rigid, sharedFactor, progress)
               : slepcKrylovSchur(stiffness, mass, layout, shift, count, tolerance, rigid, wanted, progress);
  };
  LinearModes out;
  out.rigidSkipped = static_cast<int>(rigid.cols());
  if (out.rigidSkipped > 0) {
    // K - sigma M is nearly singular for sigma just below 0: good enough to locate the first elastic
    // eigenvalue, not to compute modes accurately. Then solve again at half that value.
    const double first = solve(-1e-8 * diagonalRatio(stiffness, mass), 1, 1e-6, false).values[0];
    out.shift = -0.5 * first;
  }
  EigenPairs pairs = solve(out.shift, settings.count, settings.tolerance, true);
  out.eigenvalues = std::move(pairs.values);
  out.vectors = std::move(pairs.vectors);
  // SLEPc returns M-normalised vectors for GHEP; normalise again so the contract does not rest on it.
  const Eigen::MatrixXd Mphi = multiply(mass, out.vectors, layout);
  for (int j = 0; j < settings.count; ++j) {
    const double norm = std::sqrt(innerProducts(out.vectors.col(j), Mphi.col(j), layout.comm())(0, 0));
    out.vectors.col(j) /= norm;
  }
  layout.orientColumns(out.vectors);
  out.residuals = eigenResiduals(stiffness, mass, out.eigenvalues, out.vectors, layout);
  for (int j = 0; j < settings.count; ++j)
    if (!(out.residuals[j] <= settings.maxResidual)) {
      std::ostringstream why;
      why << "mode " << j << " (lambda = " << out.eigenvalues[j] << ") has relative residual " << out.residuals[j]
          << ", above " << settings.maxResidual
          << (settings.solver == Eigensolver::KrylovSchur ? "; tighten -eps_tol" : "; try --eigensolver krylov-schur");
      throw std::runtime_error(why.str());
    }
  return out;
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

const char* eigensolverName(Eigensolver solver) {
  return solver == Eigensolver::Block ? "block" : "krylov-schur";
}

std::string modesInputHash(const std::string& meshHash, int count, Eigensolver solver, const std::string& petscOptions) {
  return InputHash().add(meshHash).add(count).add(eigensolverName(solver)).add(petscOptions).add(kModesVersion).hex();
}

std::vector<std::string> describeModes(const LinearModes& modes) {
  const auto hz = modes.frequenciesHz();
  std::vector<std::string> lines{std::to_string(hz.size()) + " modes, " + shortNumber(hz.front()) + " to " +
                                 shortNumber(hz.back()) + " Hz, max residual " +
                                 shortNumber(*std::max_element(modes.residuals.begin(), modes.residuals.end()))};
  for (size_t i = 0; i < hz.size(); ++i)
    lines.push_back("  mode " + std::to_string(i) + ": " + shortNumber(hz[i]) + " Hz (lambda " +
                    shortNumber(modes.eigenvalues[i]) + "), residual " + shortNumber(modes.residuals[i]));
  return lines;
}

LinearModes modesStage(StageRunner& stages, const BakeContext& ctx, const AssembledSystem& system,
                       const DofLayout& layout, const Eigen::MatrixXd& rigid, int count, Eigensolver solver,
                       StiffnessFactor& factor, const std::string& inputHash) {
  bool reused = false;
  const LinearModes modes = stages.checkpointed(
      "modes", "/modes", inputHash, [&](const Archive& a) { return readModes(a, layout); },
      [&] {
        ProgressMeter meter(ctx, "modes", "converged");
        ModeSettings settings;
        settings.count = count;
        settings.solver = solver;
        settings.progress = meter.callback();
        return computeLinearModes(system.stiffness, system.mass, layout, settings, rigid, &factor);
      },
      [&](Archive& a, const LinearModes& m, const std::string& h) { writeModes(a, m, layout, h); }, reused);
  const std::vector<std::string> lines = describeModes(modes);
  stages.report(lines[0], reused);
  for (size_t i = 1; i < lines.size(); ++i) ctx.progress(lines[i]);
  return modes;
}

} // namespace quiver
