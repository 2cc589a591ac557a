#pragma once
// Static equilibria of St.Venant-Kirchhoff under dead forces and penalty springs, in full space and
// in a subspace u = U q. Each is the minimum of
//   Phi(u) = E(u) - f^T u + k/2 sum_v |u_v - d_v|^2     (d_v = target_v - X_v),
// found by Newton with backtracking on Phi, the Hessian shifted to positive definite where
// compression makes it indefinite, the loads applied in equal increments (large deformations are
// reached along their path, not jumped to). The subspace version works on E(U q) itself: it is the
// baked reduced model's energy exactly, without its polynomial, so comparing the two solutions
// measures what the basis loses and nothing else (the bake's fidelity report).
#include <functional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/stvk_force_model.h"

namespace quiver {

struct StaticLoad {
  Eigen::VectorXd force;                 // 3n, N (zero where unused)
  std::vector<int> springVertices;       // pulled toward `springTargets` with `springStiffness` N/m each
  std::vector<Eigen::Vector3d> springTargets;
  double springStiffness = 0;
};

struct StaticSettings {
  int increments = 8;        // load steps
  int maxIterations = 40;    // Newton iterations per increment
  double tolerance = 1e-9;   // |grad Phi| <= tolerance * (|f| + |spring forces at rest| + |R(u)|)
  double accepted = 1e-6;    // an increment that ends within this (rounding) still counts as converged
};

// Solves H x = b for the free DOFs' symmetric Hessian H (whole, free DOFs in vertex order, three
// per vertex), or returns false when H is not positive definite. Each Newton step calls it with
// the same pattern.
using SymmetricSolve = std::function<bool(const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& b, Eigen::VectorXd& x)>;

// Full space: `fixed` vertices stay at rest. `solve` by default Eigen's SimplicialLDLT (its order
// computed once); the bake passes a faster one. Throws std::runtime_error when an increment does
// not converge (the message says which and how far).
Eigen::VectorXd solveStatic(const StVKForceModel& model, const std::vector<Eigen::Vector3d>& rest,
                            const std::vector<int>& fixed, const StaticLoad& load, const StaticSettings& settings = {},
                            const SymmetricSolve& solve = {});

// Subspace: the equilibrium among u = U q (U: 3n x r, zero rows at fixed DOFs); returns U q.
Eigen::VectorXd solveStaticReduced(const StVKForceModel& model, const std::vector<Eigen::Vector3d>& rest,
                                   const Eigen::MatrixXd& U, const StaticLoad& load,
                                   const StaticSettings& settings = {});

} // namespace quiver
