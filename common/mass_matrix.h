#pragma once
// Mass matrices of linear tets, assembled over the 3n displacement DOFs.
//
// Both take one Material per tet (see resolveTetMaterials()) so that regions of different
// density are honoured, and both return a symmetric 3n x 3n matrix in the DOF order
// dof = 3 * vertex + component, with no coupling between the x, y and z components.
#include <vector>

#include <Eigen/SparseCore>

#include "common/tet_mesh.h"

namespace quiver {

// Weight w_ab of the consistent element mass M_e^{ab} = \rho_e V_e w_{ab} I_3: 1/10 on the
// diagonal, 1/20 off it (\int N_a N_b dV / V for linear tets).
constexpr double consistentMassWeight(int a, int b) { return a == b ? 0.1 : 0.05; }

// Consistent mass M = \sum_e M_e with, for tet vertices a, b = 0..3,
//   M_e^{ab} = \frac{\rho_e V_e}{20} (1 + \delta_{ab}) I_3,
// the exact integral \int_e \rho_e N_a N_b dV of the linear shape functions. It integrates
// products of linear fields exactly (total mass, first and second moments).
// Throws std::invalid_argument when perTet.size() != mesh.tetCount().
Eigen::SparseMatrix<double> consistentMassMatrix(const TetMesh& mesh, const std::vector<Material>& perTet);

// Lumped (diagonal) mass: each tet gives \rho_e V_e / 4 to each of its vertices, i.e. the row
// sums of the consistent mass. It integrates constants and linear fields exactly, not their
// products. Same preconditions as consistentMassMatrix().
Eigen::SparseMatrix<double> lumpedMassMatrix(const TetMesh& mesh, const std::vector<Material>& perTet);

} // namespace quiver
