#pragma once
// Stage "derivatives": modal derivatives K Psi_ij = -d^2R[phi_i, phi_j] for i <= j <= k (Barbič &
// James 2005), the second derivative of the internal force at rest applied to two modes. Each rank
// computes the right-hand sides of its rows exactly (stvkElementForceHessiansAtRest); all k(k+1)/2
// are solved in blocks with one Cholesky factorization of K (DirectSolver: the same bits every run),
// the modes' own when they were computed at shift 0 in the same run.
// On a free object K is singular: the right-hand sides are projected off the rigid modes, six
// DOFs are pinned to pick one solution, and the result is made M-orthogonal to the rigid modes.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <petscmat.h>

#include "common/tet_mesh.h"
#include "precompute/archive/archive.h"
#include "precompute/direct_solver.h"
#include "precompute/dof_layout.h"
#include "precompute/progress_meter.h"
#include "precompute/stages/modes.h"

namespace quiver {

struct DerivativeSettings {
  double maxResidual = 1e-10;  // refuse solutions with ||K Psi - b|| / (||K||_1 ||Psi|| + ||b||) above this
  int blockSize = 32;         // right-hand sides per solve call, so that progress can be reported
  ProgressCallback progress;  // (solved, total); optional
};

struct ModalDerivatives {
  std::vector<std::array<int, 2>> pairs;  // (i, j), i <= j, in order (0,0), (0,1), ..., (k-1,k-1)
  Eigen::MatrixXd vectors;                // this rank's rows, one column per pair
  std::vector<double> residuals;          // ||K Psi - b|| / (||K||_1 ||Psi|| + ||b||) per pair
};

// Collective. `rigid` is rigidModes() on a free object and empty (0 columns) otherwise; a fixed
// object solves with `sharedFactor` when given.
ModalDerivatives computeModalDerivatives(const TetMesh& mesh, const std::vector<Material>& perTet, Mat stiffness,
                                         Mat mass, const DofLayout& layout, const LinearModes& modes,
                                         const Eigen::MatrixXd& rigid, const DerivativeSettings& settings,
                                         StiffnessFactor* sharedFactor = nullptr);

// Checkpoint: group /derivatives. Input hash: the modes' and the stage's version tag (2: residuals
// are normwise backward errors; 3: on several ranks, a sequential factor per rank, issue #16; 4: the
// right-hand sides summed in tet order on every rank count).
inline constexpr const char* kDerivativesVersion = "derivatives 4";
std::string derivativesInputHash(const std::string& modesHash);
void writeDerivatives(Archive& archive, const ModalDerivatives& derivatives, const DofLayout& layout,
                      const std::string& inputHash);
ModalDerivatives readDerivatives(const Archive& archive, const DofLayout& layout);
// Progress: "210 solved, max residual 4e-17".
std::string describeDerivatives(const ModalDerivatives& derivatives);

// The stage as the bake runs it: checkpointed under `inputHash`, with its progress line.
ModalDerivatives derivativesStage(StageRunner& stages, const BakeContext& ctx, const TetMesh& mesh,
                                  const std::vector<Material>& perTet, const AssembledSystem& system, const DofLayout& layout, const LinearModes& modes,
                                  const Eigen::MatrixXd& rigid, StiffnessFactor& factor, const std::string& inputHash);

} // namespace quiver
