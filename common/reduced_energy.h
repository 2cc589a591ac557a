#pragma once
// The reduced St.Venant-Kirchhoff energy E(q) = sum_e V_e W(E_e(Uq)) of a basis U, as an exact
// quartic in q (Barbič & James 2005, without cubature: strain is constant on a linear tet). Its
// gradient is the reduced internal force U^T R(Uq) (cubic), its Hessian U^T K(Uq) U (quadratic).
//
// Per tet, with G_j = \sum_a U_{a,j} g_a^T, the Green strain as a 6-vector (xx, yy, zz, yz, xz, xy)
// is e(q) = L_e q + S_e z(q): column j of L_e is sym(G_j), column (j,k) of S_e is sym(G_j^T G_k)
// (j < k) or G_j^T G_j / 2 (j = k), and z holds the P = r(r+1)/2 products q_j q_k (j <= k). With
// D_e = V(\mu W + \tfrac{\lambda}{2} t t^T), W = diag(1,1,1,2,2,2), t = (1,1,1,0,0,0), the energy is
//   \sum_e e^T D_e e = q^T A_2 q + 2 q^T A_3 z + z^T A_4 z,   [A_2 A_3; A_3^T A_4] = \sum_e B_e^T B_e,
// with B_e = C_e [L_e S_e] and D_e = C_e^T C_e (6x6 Cholesky). The bake stacks the B_e of many
// tets and sums them with one BLAS rank-k update per block over MPI ranks
// (precompute/stages/polynomials.h); reducedEnergyGram is the same sum, serial, for references
// and tests. The Gram matrix becomes the .qvr's monomial coefficients in formats/model/qvr_writer.h.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/material.h"
#include "common/tet_elements.h"

namespace quiver {

// Writes the six rows of B_e, tet after tet; its scratch is sized once so the loop allocates nothing.
// It keeps the basis rows of the tets it will see vertex-major (each vertex's 3 x r block
// contiguous: a tet reads four runs of memory) and builds each tet's G_j entry by entry as arrays
// over j, so that the products G_j^T G_k, and the rows of B_e, run as vector loops over k.
class ReducedEnergyRows {
public:
  // `basis`: 3n x r, vertex order; `tets`: the tets of `mesh` that write() will be given.
  ReducedEnergyRows(const Eigen::MatrixXd& basis, const TetMesh& mesh, const std::vector<int>& tets);
  static int columns(int r) { return r + r * (r + 1) / 2; }
  int columns() const { return columns(r_); }

  // B_e (6 x columns()) row by row: row i at B + i * ld (ld >= columns()).
  void write(const Tet& tet, const Matrix34& gradients, double volume, const Material& material, double* B, int64_t ld);

private:
  int r_;
  std::vector<int> row_;  // vertex -> its block in vertexMajor_ (-1: no tet of ours uses it)
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> vertexMajor_;  // 3 rows per used vertex
  std::vector<double> g_;      // G_j(c, d) at [(3 c + d) r + j]
  std::vector<double> strain_; // one row j of the products: the 6 Voigt components over k, [component r + k]
};

// sum_e B_e^T B_e over every tet (upper triangle filled).
Eigen::MatrixXd reducedEnergyGram(const TetMesh& mesh, const std::vector<Material>& perTet,
                                  const Eigen::MatrixXd& basis);

} // namespace quiver
