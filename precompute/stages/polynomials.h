#pragma once
// Stage "polynomials": the reduced St.Venant-Kirchhoff energy of the basis as an exact quartic
// in q (the maths: common/reduced_energy.h). Each MPI rank stacks the rows B_e of its own tets in
// blocks and sums B^T B with one symmetric rank-k update (BLAS dsyrk) per block: dense algebra at
// the machine's peak rather than scalar loops. A rank's tets are cut into a fixed number of
// slices, each summed into a Gram of its own by whichever of the rank's threads takes it, and the
// Grams added in slice order: the cores a rank has work on it, and the sums' bits do not depend on
// how many there are. One reduction adds the ranks' sums, folded into the .qvr's monomial
// coefficients.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <mpi.h>

#include "common/tet_mesh.h"
#include "precompute/archive/archive.h"
#include "precompute/progress_meter.h"
#include "precompute/stage_runner.h"

namespace quiver {

struct PolynomialSettings {
  // Tets stacked per dsyrk call (6 rows each). 32: the block (0.76 MB at r = 30) is still in L2
  // when the dsyrk reads it; 256 took 10% longer at r = 30 (bench/README.md).
  int tetsPerBlock = 32;
  // Threads summing the slices (at most their number, gramSlices()); the calling thread is one.
  int threads = 1;
  ProgressCallback progress;  // (tets done on this rank, tets of this rank), on the calling thread, ending at all; optional
};

// The slices a rank's `tets` are cut into for Grams of N x N: four, fewer where four Grams would
// take more than 1 GiB (r > 100) or where there are fewer tets.
int gramSlices(int N, size_t tets);

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

// Checkpoint: group /polynomials. Input hash: the basis's and the stage's version tag.
inline constexpr const char* kPolynomialsVersion = "polynomials 2";
std::string polynomialInputHash(const std::string& basisHash);
void writePolynomial(Archive& archive, const EnergyPolynomial& energy, const std::string& inputHash);
EnergyPolynomial readPolynomial(const Archive& archive);
// Progress: "46345 energy coefficients (exact, r = 30), 42 us per tet, 2 threads per rank".
std::string describePolynomial(const EnergyPolynomial& energy, int tets, double seconds, int threads);

// The stage as the bake runs it, on `threads` threads per rank: checkpointed under `inputHash`,
// with its progress line.
EnergyPolynomial polynomialStage(StageRunner& stages, const BakeContext& ctx, const TetMesh& mesh,
                                 const std::vector<Material>& perTet, const std::vector<int>& tetPart,
                                 const Eigen::MatrixXd& basis, const std::string& inputHash, int threads);

} // namespace quiver
