#pragma once
// Stage "polynomials": the reduced St.Venant-Kirchhoff energy E(q) = sum_e V_e W(E_e(Uq)) as an
// exact quartic polynomial in q (Barbič & James 2005, without cubature: strain is constant on a
// linear tet). Its gradient is the reduced internal force U^T R(Uq) (cubic) and its Hessian the
// reduced stiffness U^T K(Uq) U (quadratic).
//
// Per tet, with G_j = \sum_a U_{a,j} g_a^T, the Green strain as a 6-vector (xx, yy, zz, yz, xz, xy)
// is e(q) = L_e q + S_e z(q): column j of L_e is sym(G_j), column (j,k) of S_e is sym(G_j^T G_k)
// (j < k) or G_j^T G_j / 2 (j = k), and z holds the P = r(r+1)/2 products q_j q_k (j <= k). With
// D_e = V(\mu W + \tfrac{\lambda}{2} t t^T), W = diag(1,1,1,2,2,2), t = (1,1,1,0,0,0), the energy is
//   \sum_e e^T D_e e = q^T A_2 q + 2 q^T A_3 z + z^T A_4 z,   [A_2 A_3; A_3^T A_4] = \sum_e B_e^T B_e,
// with B_e = C_e [L_e S_e] and D_e = C_e^T C_e (6x6 Cholesky). The sum is one symmetric rank-k
// update (BLAS dsyrk) over the tets stacked in blocks: dense algebra at the machine's peak rather
// than scalar loops. Each MPI rank sums its own tets; one reduction adds the ranks' sums.
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <mpi.h>

#include "common/tet_mesh.h"
#include "precompute/progress_meter.h"

namespace quiver {

struct PolynomialSettings {
  int tetsPerBlock = 256;     // tets stacked per dsyrk call (6 rows each)
  ProgressCallback progress;  // (tets done on this rank, tets of this rank); optional
};

// Unique coefficients of E(q) over sorted monomials, degree 2 then 3 then 4, each in the order
// of formats/model/qvr.h (monomialIndex2/3/4): the .qvr ENERGY_COEFFICIENTS layout.
struct EnergyPolynomial {
  int r = 0;
  std::vector<double> coefficients;
};

// `basis`: the full 3n x r basis in vertex order (zeros at fixed DOFs), the same on every rank;
// this rank integrates the tets with tetPart[t] == its rank. Collective: every rank gets the sum.
EnergyPolynomial computeEnergyPolynomial(MPI_Comm comm, const TetMesh& mesh, const std::vector<Material>& perTet,
                                         const std::vector<int>& tetPart, const Eigen::MatrixXd& basis,
                                         const PolynomialSettings& settings);

} // namespace quiver
