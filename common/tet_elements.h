#pragma once
// Per-tet geometry of linear tetrahedra: rest volume and shape-function gradients.
//
// On a linear tet the shape functions N_a (a = 0..3) are affine, so their gradients g_a are
// constant and everything built from them (deformation gradient, strain, stress) is constant
// per tet. Precomputing V and g_a once turns every later element loop into small fixed-size
// products.
#include <vector>

#include <Eigen/Core>

#include "common/tet_mesh.h"

namespace quiver {

// Four 3-vectors side by side, one column per tet vertex.
using Matrix34 = Eigen::Matrix<double, 3, 4>;

struct TetElements {
  // Rest volume V = |\det D_m| / 6, with D_m = [X_1 - X_0, X_2 - X_0, X_3 - X_0].
  std::vector<double> volume;
  // Column a is g_a = \nabla N_a: for a = 1..3 the (a-1)-th row of D_m^{-1} (transposed),
  // and g_0 = -(g_1 + g_2 + g_3) because the N_a sum to one.
  std::vector<Matrix34> gradients;

  int count() const { return static_cast<int>(volume.size()); }
};

// V and g_a for every tet of `mesh`, in tet order. Either orientation is accepted (V uses
// |det D_m|). Throws std::invalid_argument naming the tet when D_m is singular or not finite.
TetElements computeTetElements(const TetMesh& mesh);

// The displacements of the tet's four vertices as columns: column a = u_{tet[a]}, read from
// `u` in the DOF order dof = 3 * vertex + component.
Matrix34 tetDisplacements(const Tet& tet, const Eigen::VectorXd& u);

// Displacement gradient H = \sum_a u_a g_a^T = U_e G^T, with U_e = tetDisplacements() and
// G = TetElements::gradients of the same tet; the deformation gradient is F = I + H.
Eigen::Matrix3d displacementGradient(const Matrix34& ue, const Matrix34& gradients);

} // namespace quiver
