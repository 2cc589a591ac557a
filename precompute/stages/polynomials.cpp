#include "precompute/stages/polynomials.h"

#include <algorithm>

#include <cblas.h>

#include "common/reduced_energy.h"
#include "formats/model/qvr_writer.h"
#include "precompute/checkpoint.h"
#include "precompute/input_hash.h"

namespace quiver {

EnergyPolynomial computeEnergyPolynomial(MPI_Comm comm, const TetMesh& mesh, const std::vector<Material>& perTet,
                                         const std::vector<int>& tetPart, const Eigen::MatrixXd& basis,
                                         const PolynomialSettings& settings) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const int r = static_cast<int>(basis.cols());
  std::vector<int> mine;
  for (int t = 0; t < mesh.tetCount(); ++t)
    if (tetPart[t] == rank) mine.push_back(t);
  ReducedEnergyRows rows(basis, mesh, mine);
  const int N = rows.columns();

  const TetElements elements = computeTetElements(mesh);
  const int block = std::max(1, settings.tetsPerBlock);
  // The block's rows B_e^T side by side: N x 6 block, column-major (each row of B_e one contiguous run).
  std::vector<double> B(6 * static_cast<size_t>(block) * N);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(N, N);
  for (size_t first = 0; first < mine.size(); first += block) {
    const int count = static_cast<int>(std::min<size_t>(block, mine.size() - first));
    for (int b = 0; b < count; ++b) {
      const int t = mine[first + b];
      rows.write(mesh.tets[t], elements.gradients[t], elements.volume[t], perTet[t], B.data() + 6 * b * static_cast<int64_t>(N), N);
    }
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, N, 6 * count, 1.0, B.data(), N, 1.0, gram.data(), N);
    if (settings.progress) settings.progress(static_cast<int64_t>(first + count), static_cast<int64_t>(mine.size()));
  }
  EnergyPolynomial out;
  out.r = r;
  const std::vector<double> local = energyCoefficientsFromGram(gram.data(), N, r);
  out.coefficients.resize(local.size());
  MPI_Allreduce(local.data(), out.coefficients.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, comm);
  return out;
}

void writePolynomial(Archive& archive, const EnergyPolynomial& energy, const std::string& inputHash) {
  resetGroup(archive, "/polynomials");
  writeVector(archive, "/polynomials/energy_coefficients", energy.coefficients);
  archive.setAttribute("/polynomials", "r", static_cast<int64_t>(energy.r));
  finishGroup(archive, "/polynomials", inputHash);
}

EnergyPolynomial readPolynomial(const Archive& archive) {
  EnergyPolynomial energy;
  energy.r = static_cast<int>(archive.intAttribute("/polynomials", "r"));
  energy.coefficients = readVector(archive, "/polynomials/energy_coefficients");
  return energy;
}

std::string polynomialInputHash(const std::string& basisHash) {
  return InputHash().add(basisHash).add(kPolynomialsVersion).hex();
}

std::string describePolynomial(const EnergyPolynomial& energy, int tets, double seconds) {
  return std::to_string(energy.coefficients.size()) + " energy coefficients (exact, r = " + std::to_string(energy.r) +
         "), " + shortNumber(1e6 * seconds / tets) + " us per tet";
}

EnergyPolynomial polynomialStage(StageRunner& stages, const BakeContext& ctx, const TetMesh& mesh,
                                 const std::vector<Material>& perTet, const std::vector<int>& tetPart,
                                 const Eigen::MatrixXd& basis, const std::string& inputHash) {
  bool reused = false;
  const EnergyPolynomial energy = stages.checkpointed(
      "polynomials", "/polynomials", inputHash, [&](const Archive& a) { return readPolynomial(a); },
      [&] {
        ProgressMeter meter(ctx, "polynomials", "tets integrated (rank 0)");
        PolynomialSettings settings;
        settings.progress = meter.callback();
        return computeEnergyPolynomial(ctx.comm(), mesh, perTet, tetPart, basis, settings);
      },
      [&](Archive& a, const EnergyPolynomial& e, const std::string& h) { writePolynomial(a, e, h); }, reused);
  stages.report(describePolynomial(energy, mesh.tetCount(), stages.last()), reused);
  return energy;
}

} // namespace quiver
