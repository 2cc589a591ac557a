#pragma once
// Stage "polynomials": the reduced St.Venant-Kirchhoff energy of the basis as an exact quartic
// in q (the maths: common/reduced_energy.h). Each MPI rank stacks the rows B_e of its own tets in
// blocks and sums B^T B with one symmetric rank-k update (BLAS dsyrk) per block: dense algebra at
// the machine's peak rather than scalar loops. One reduction adds the ranks' sums, folded into the
// .qvr's monomial coefficients.
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
