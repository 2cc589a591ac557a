#pragma once
// The full-space St.Venant-Kirchhoff reference simulator: every vertex's three DOFs, the same
// implicit Newmark scheme as the runtime (beta = 1/4, gamma = 1/2) but with Newton iterated to
// convergence on the sparse tangent, Rayleigh damping C = alpha M + beta K(u), and the runtime's
// loads (vertex forces, gravity, penalty springs pulling vertices to targets). It is the yardstick
// the reduced model is measured against: seconds per simulated second, and displacement error.
//
// Fixed vertices keep zero displacement: their rows and columns of the system become the
// identity on the tangent's fixed pattern, so the sparsity pattern (and a direct solver's
// symbolic factorisation, computed once) never changes.
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/SparseCore>

#include "common/stvk_force_model.h"
#include "quiver/quiver.h"

namespace quiver {

enum class SparseSolver { LLT, LDLT, CG, LU };


// "llt", "ldlt", "cg", "lu"; throws std::invalid_argument for anything else.
SparseSolver parseSparseSolver(const std::string& name);

struct FullSpaceSettings {
  double timeStep = 1.0 / 60;      // s, > 0
  double rayleighAlpha = 0;        // 1/s, mass-proportional damping
  double rayleighBeta = 0;         // s, stiffness-proportional damping
  int maxNewtonIterations = 20;    // per step
  double newtonTolerance = 1e-8;   // stop when ||residual|| <= tolerance * (||M a|| + ||f|| + tiny)
  SparseSolver solver = SparseSolver::LDLT;
  // The runtime's choices, in full space: St.Venant-Kirchhoff; linear elasticity (R = K(0) u); or
  // linear elasticity with per-vertex modal warping of the output (Choi & Ko 2005, every free DOF a
  // mode: the full linear system).
  qv_elasticity elasticity = QV_ELASTICITY_STVK;
  double cgTolerance = 1e-12;      // relative residual of each CG solve
};

class FullSpaceSimulator {
public:
  FullSpaceSimulator(const TetMesh& mesh, const std::vector<Material>& perTet, const std::vector<int>& fixedVertices,
                     const FullSpaceSettings& settings);
  ~FullSpaceSimulator();

  // Loads, as in the runtime: per-step vertex forces (N), persistent gravity (m/s^2) and penalty
  // springs of `stiffness` (N/m) pulling `vertices` toward `targets` (3 per vertex).
  void addVertexForce(int vertex, const Eigen::Vector3d& force);
  void setGravity(const Eigen::Vector3d& acceleration);
  void setSprings(const std::vector<int>& vertices, const std::vector<Eigen::Vector3d>& targets, double stiffness);
  void clearSprings();

  // One time step; returns the Newton iterations used (over all substeps). When Newton does not
  // converge the step is retried as two half steps, recursively down to 1/64 of it. Throws
  // std::runtime_error when the linear solver fails (e.g. SimplicialLLT on an indefinite tangent)
  // or Newton fails even then.
  int step();

  // The displacement to show: u, or under warping each vertex's u rotated by its local rotation
  // (1/2 curl u, volume-averaged over its tets).
  Eigen::VectorXd displacement() const;
  const Eigen::VectorXd& velocity() const { return v_; }
  double kineticEnergy() const;
  double elasticEnergy() const;
  int dofCount() const { return model_.dofCount(); }

private:
  struct NewtonFailure : std::runtime_error {
    using std::runtime_error::runtime_error;
  };
  int advance(double h, int depth);
  int newmarkStep(double h);
  void applyConstraints(Eigen::SparseMatrix<double>& A, Eigen::VectorXd& b) const;
  void solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, Eigen::VectorXd& x);

  StVKForceModel model_;
  FullSpaceSettings settings_;
  Eigen::SparseMatrix<double> mass_, tangent_, system_;
  std::vector<char> fixedDof_;
  std::vector<int> constrainedSlots_;  // value-array indices of entries in fixed rows or columns
  Eigen::VectorXd u_, v_, a_, stepForce_, gravityForce_, force_;
  std::vector<int> springVertices_;
  std::vector<Eigen::Vector3d> springTargets_;
  double springStiffness_ = 0;
  std::vector<Eigen::Vector3d> rest_;
  TetMesh mesh_;                       // for the rotations of warping
  Eigen::SparseMatrix<double> restStiffness_;  // K(0), for linear elasticity and warping
  std::vector<int> diagonalSlot_;      // value-array index of each DOF's diagonal entry
  struct Solvers;
  std::unique_ptr<Solvers> solvers_;
  bool analyzed_ = false;
};

} // namespace quiver
