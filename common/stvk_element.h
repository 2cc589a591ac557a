#pragma once
// St.Venant-Kirchhoff kernels of one linear tet: strain, stress, energy density, the element's
// nodal forces and tangent, and the second derivative of its forces at rest (the right-hand side
// of modal derivatives). StVKForceModel assembles them over a whole mesh; the bake assembles them
// over the tets each MPI rank owns.
//
// With the displacement gradient H = \sum_a u_a g_a^T constant on the tet and F = I + H:
//   E = \tfrac12 (H + H^T + H^T H),  S = 2\mu E + \lambda \operatorname{tr}(E) I,  P = F S,
//   W = \mu E:E + \tfrac{\lambda}{2} (\operatorname{tr} E)^2,  f_a = V P g_a.
#include <Eigen/Core>

#include "common/tet_elements.h"

namespace quiver {

using Matrix12 = Eigen::Matrix<double, 12, 12>;

// Green strain from the displacement gradient H = F - I: E = \tfrac12 (H + H^T + H^T H), the same as
// \tfrac12 (F^T F - I) but without its cancellation: at strains of 1e-8 the latter keeps half the digits.
Eigen::Matrix3d greenStrain(const Eigen::Matrix3d& H);

// StVK second Piola-Kirchhoff stress S = \partial W / \partial E = 2 \mu E + \lambda \operatorname{tr}(E) I.
Eigen::Matrix3d stvkSecondPiolaKirchhoff(const Eigen::Matrix3d& E, double lambda, double mu);

// StVK energy density W = \mu E:E + \tfrac{\lambda}{2} (\operatorname{tr} E)^2, per unit rest volume.
double stvkEnergyDensity(const Eigen::Matrix3d& E, double lambda, double mu);

// Nodal internal forces f_a = V P g_a (column a), P = F S(E), for the displacement gradient H.
Matrix34 stvkElementForce(const Eigen::Matrix3d& H, const Matrix34& G, double V, double lambda, double mu);

// Element tangent \partial f / \partial u_e (rows and columns 3a + i), symmetric:
//   K^{ab} = V [ (g_a^T S g_b) I + \mu (g_a \cdot g_b) F F^T + \mu F g_b (F g_a)^T + \lambda F g_a (F g_b)^T ].
Matrix12 stvkElementTangent(const Eigen::Matrix3d& H, const Matrix34& G, double V, double lambda, double mu);

// Second derivative of the nodal forces at rest along displacements a and b of the tet's
// vertices (columns as in tetDisplacements()): d^2 f [a, b] = \partial_s \partial_t f(s a + t b)
// at s = t = 0. With H_a = a G^T, \delta S_a = 2\mu\,\mathrm{sym} H_a + \lambda \operatorname{tr}(H_a) I and
// \delta^2 S_{ab} = 2\mu\,\mathrm{sym}(H_a^T H_b) + \lambda \operatorname{tr}(H_a^T H_b) I:
//   d^2 P[a, b] = H_a \delta S_b + H_b \delta S_a + \delta^2 S_{ab},   d^2 f_c = V\, d^2P\, g_c.
// Symmetric in (a, b); equals the derivative of the tangent at rest along b applied to a.
Matrix34 stvkElementForceHessianAtRest(const Matrix34& a, const Matrix34& b, const Matrix34& G, double V,
                                       double lambda, double mu);

// The same for every pair i <= j of k directions on one tet (modal derivatives' right-hand sides
// need all k(k+1)/2): each direction's H and \delta S once, then the pairs with one i side by side,
// so the sums vectorise across j. Direction i is columns 4i..4i+3 of `directions`. Pair (i, j)'s
// d^2 f is column p of the row-major 12 x k(k+1)/2 block at `out` (row 3c + i: vertex c, component
// i; rows `ld` apart), pairs in the order (0,0), (0,1), ..., (0,k-1), (1,1), ..., (k-1,k-1).
void stvkElementForceHessiansAtRest(const Eigen::Matrix<double, 3, Eigen::Dynamic>& directions, const Matrix34& G,
                                    double V, double lambda, double mu, double* out, Eigen::Index ld);

} // namespace quiver
