#pragma once
// Stage "modes": the lowest vibration modes K phi = lambda M phi of the free DOFs by shift-and-invert
// with a direct solver, the same bits every run: by default a block Krylov-Schur
// iteration over a Cholesky factor (block_eigensolver.h, DirectSolver: about 8 ms a right-hand side
// in blocks of 8 against 45 ms for one alone on a 97k-tet torus), or SLEPc's
// Krylov-Schur (--eigensolver krylov-schur; MUMPS on one rank, SuperLU_DIST on two, a sequential
// MUMPS factor per rank on more; its -eps_* / -st_* options apply). On a free object (no fixed
// vertex) K is singular: the six rigid motions are deflated (the solver works M-orthogonally to
// them), and the shift is placed below zero at half the first elastic eigenvalue, which a cheap
// first solve estimates; so K - sigma M is definite and as well conditioned as on a clamped object.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <petscmat.h>

#include "precompute/archive/archive.h"
#include "precompute/direct_solver.h"
#include "precompute/dof_layout.h"
#include "precompute/progress_meter.h"
#include "precompute/stage_runner.h"
#include "precompute/stages/assemble.h"

namespace quiver {

enum class Eigensolver { Block, KrylovSchur };
// "block" or "krylov-schur".
const char* eigensolverName(Eigensolver solver);

struct ModeSettings {
  int count = 20;            // k, elastic modes wanted (>= 1)
  Eigensolver solver = Eigensolver::Block;
  double tolerance = 1e-12;  // on ||(K - sigma M)^-1 M phi - theta phi||: block_eigensolver.h; krylov-schur: SLEPc's (-eps_tol overrides)
  double maxResidual = 1e-8; // refuse pairs with ||K phi - lambda M phi|| / (||K||_1 ||phi||) above this
  ProgressCallback progress; // (converged, wanted) as the solver iterates; optional
};

struct LinearModes {
  std::vector<double> eigenvalues;  // ascending, (rad/s)^2
  std::vector<double> residuals;    // ||K phi - lambda M phi|| / (||K||_1 ||phi||), each below maxResidual
  Eigen::MatrixXd vectors;          // this rank's rows (layout.localDofs() x k), M-orthonormal, oriented
  int rigidSkipped = 0;             // 6 on a free object (deflated rigid motions)
  double shift = 0;                 // sigma used for shift-and-invert

  // f = sqrt(lambda) / (2 pi), in Hz.
  std::vector<double> frequenciesHz() const;
};

// `rigid`: on a free object, rigidModes() (this rank's rows); empty (0 columns) when vertices are
// fixed. At shift 0 the block solver factors K through `sharedFactor` when given (the derivatives
// reuse it). Collective. Throws std::runtime_error when the solver fails or does not converge, or
// when the residual check fails.
LinearModes computeLinearModes(Mat stiffness, Mat mass, const DofLayout& layout, const ModeSettings& settings,
                               const Eigen::MatrixXd& rigid, StiffnessFactor* sharedFactor = nullptr);

// ||K phi_i - lambda_i M phi_i|| / (||K||_1 ||phi_i||) for the columns of `vectors` (local rows).
std::vector<double> eigenResiduals(Mat stiffness, Mat mass, const std::vector<double>& eigenvalues,
                                   const Eigen::MatrixXd& vectors, const DofLayout& layout);

// Checkpoint: group /modes. Input hash: the mesh stage's, k, the solver, the PETSc/SLEPc options
// given, and the stage's version tag (2: the solvers that give the same bits every run on several
// ranks; 3: the block solver; 4: K and M summed in tet order on every rank count).
inline constexpr const char* kModesVersion = "modes 4";
std::string modesInputHash(const std::string& meshHash, int count, Eigensolver solver, const std::string& petscOptions);
void writeModes(Archive& archive, const LinearModes& modes, const DofLayout& layout, const std::string& inputHash);
LinearModes readModes(const Archive& archive, const DofLayout& layout);
// Progress: "20 modes, 0.81 to 50 Hz, max residual 1e-16", then a line per mode.
std::vector<std::string> describeModes(const LinearModes& modes);

// The stage as the bake runs it: checkpointed under `inputHash`, with its progress lines.
LinearModes modesStage(StageRunner& stages, const BakeContext& ctx, const AssembledSystem& system,
                       const DofLayout& layout, const Eigen::MatrixXd& rigid, int count, Eigensolver solver,
                       StiffnessFactor& factor, const std::string& inputHash);

} // namespace quiver
