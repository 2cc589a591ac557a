#pragma once
// The mass moments a free object's moving frame needs (the floating frame of reference of
// reduced deformables in flight). With the density rho of the rest mesh, integrated exactly by
// the consistent mass of linear tets, and body-frame positions p = X - c + U q:
//   m        = \int \rho                       total mass
//   c        = \frac{1}{m} \int \rho X         centre of mass at rest
//   S0_{ab}  = \int \rho (X - c)_a (X - c)_b   second moments about c
//   B_{ab,j} = \int \rho (X - c)_a U_{b,j}     rest shape against the basis
//   A_{ab,jk}= \int \rho U_{a,j} U_{b,k}       the basis against itself (\sum_a A_{aa} = U^T M U)
// so that \int \rho p_a p_b = S0_{ab} + B_{ab} q + B_{ba} q + q^T A_{ab} q: the deformed body's
// inertia, and with q' its internal angular momentum and the inertial forces of a rotating frame
// on q. A basis M-orthogonal to translations (a free bake's) keeps the centre of mass at c.
#include <vector>

#include <Eigen/Core>

#include "common/tet_mesh.h"

namespace quiver {

// The rest shape's m, c and S0 alone: summed tet by tet, cheap at any mesh size. Throws
// std::invalid_argument unless there is one material per tet.
struct RestMoments {
  double mass = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d secondMoment = Eigen::Matrix3d::Zero();  // S0, symmetric to the bit
};
RestMoments restMoments(const TetMesh& mesh, const std::vector<Material>& perTet);

struct RigidBodyMoments {
  double mass = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix3d secondMoment = Eigen::Matrix3d::Zero();  // S0
  Eigen::MatrixXd first;                 // 9 x r: row 3a + b is B_{ab}
  std::vector<Eigen::MatrixXd> second;   // 9 matrices r x r: [3a + b] is A_{ab}
};

// `basis`: 3n x r in vertex order (row 3v + a), or 3n x 0 for the rest shape's moments alone.
// Throws std::invalid_argument on mismatched sizes.
RigidBodyMoments rigidBodyMoments(const TetMesh& mesh, const std::vector<Material>& perTet,
                                  const Eigen::MatrixXd& basis);

// The inertia tensor about the centre, I = tr(S) 1 - S, of second moments S.
inline Eigen::Matrix3d inertiaTensor(const Eigen::Matrix3d& secondMoment) {
  return secondMoment.trace() * Eigen::Matrix3d::Identity() - secondMoment;
}

} // namespace quiver
