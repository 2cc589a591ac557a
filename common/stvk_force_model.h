#pragma once
// St.Venant-Kirchhoff hyperelasticity on linear tets: energy, internal force and tangent
// stiffness of the full 3n-DOF displacement field.
//
// With the deformation gradient F of a tet (constant on it, see tet_elements.h), the Green
// strain and the StVK energy density are
//   E = \tfrac12 (F^T F - I),   W(E) = \mu E:E + \tfrac{\lambda}{2} (\operatorname{tr} E)^2,
// and the total energy is \sum_e V_e W(E_e), exact because E is constant per tet.
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "common/stvk_element.h"
#include "common/tet_elements.h"
#include "common/tet_mesh.h"

namespace quiver {

// The full-space StVK model of one mesh. Immutable after construction, so one instance can
// serve several threads; it keeps its own copy of the connectivity, not a reference to the mesh.
//
// Displacements and forces are 3n-vectors in the DOF order dof = 3 * vertex + component.
class StVKForceModel {
public:
  // perTet holds one material per tet (see resolveTetMaterials()); only its Lamé parameters
  // are used. Throws std::invalid_argument when its size is not mesh.tetCount() or a tet is
  // degenerate.
  StVKForceModel(const TetMesh& mesh, const std::vector<Material>& perTet);

  int dofCount() const { return 3 * vertexCount_; }
  const std::vector<Tet>& tets() const { return tets_; }
  const TetElements& elements() const { return elements_; }
  // Lamé parameters of tet t.
  double lambda(int t) const { return lambda_[t]; }
  double mu(int t) const { return mu_[t]; }

  // Elastic energy \sum_e V_e W(E_e(u)); zero at u = 0 and under any rigid motion.
  double energy(const Eigen::VectorXd& u) const;

  // Internal force R(u) = \partial energy / \partial u, the sign of M \ddot u + R(u) = f_ext: the
  // elastic force acting on the vertices is -R. Zero at u = 0.
  // Tet e contributes V_e P g_a to its vertex a, with the first Piola-Kirchhoff stress P = F S.
  // `f` is resized to dofCount() (no allocation when it already has that size).
  void internalForce(const Eigen::VectorXd& u, Eigen::VectorXd& f) const;

  // Second derivative of R at rest along displacements a and b, \partial_s \partial_t R(s a + t b) at
  // s = t = 0 (= the derivative of K at rest along b, applied to a): the right-hand side of the
  // modal derivatives K \Psi_{ij} = -d^2R[\phi_i, \phi_j]. Tet e contributes
  // stvkElementForceHessianAtRest(). `out` is resized to dofCount().
  void forceHessianAtRest(const Eigen::VectorXd& a, const Eigen::VectorXd& b, Eigen::VectorXd& out) const;

  // Tangent stiffness K(u) = \partial R / \partial u, symmetric, stored in full (both triangles)
  // on the fixed pattern of all vertex pairs that share a tet. K(0) is linear elasticity; under
  // large compression K(u) can be indefinite.
  // Tet e contributes stvkElementTangent().
  Eigen::SparseMatrix<double> tangentStiffness(const Eigen::VectorXd& u) const;

  // Same, refilling `K` in place. When K already has this model's pattern (it was returned by
  // tangentStiffness() of this model; checked by size and non-zero count) only its values are
  // overwritten: no allocation and no searching. Otherwise K is first given the pattern.
  void tangentStiffness(const Eigen::VectorXd& u, Eigen::SparseMatrix<double>& K) const;

private:
  void checkSize(const Eigen::VectorXd& u) const;

  int vertexCount_;
  std::vector<Tet> tets_;
  std::vector<double> lambda_, mu_;
  TetElements elements_;
  Eigen::SparseMatrix<double> pattern_; // compressed, values all zero
  // For tet e, slots_[144 e + 12 c + r] is the index into pattern_'s value array of element
  // row r = 3a + i, column c = 3b + j (column-major, like Eigen's 12x12 element matrix).
  std::vector<int> slots_;
};

} // namespace quiver
