#include "precompute/stages/polynomials.h"

#include <algorithm>

#include <cblas.h>

#include "common/reduced_energy.h"
#include "formats/model/qvr_writer.h"

namespace quiver {

EnergyPolynomial computeEnergyPolynomial(MPI_Comm comm, const TetMesh& mesh, const std::vector<Material>& perTet,
                                         const std::vector<int>& tetPart, const Eigen::MatrixXd& basis,
                                         const PolynomialSettings& settings) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const int r = static_cast<int>(basis.cols());
  ReducedEnergyRows rows(r);
  const int N = rows.columns();
  std::vector<int> mine;
  for (int t = 0; t < mesh.tetCount(); ++t)
    if (tetPart[t] == rank) mine.push_back(t);

  const TetElements elements = computeTetElements(mesh);
  const int block = std::max(1, settings.tetsPerBlock);
  const int64_t ld = 6 * static_cast<int64_t>(block);
  std::vector<double> B(static_cast<size_t>(ld) * N);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(N, N);
  for (size_t first = 0; first < mine.size(); first += block) {
    const int count = static_cast<int>(std::min<size_t>(block, mine.size() - first));
    for (int b = 0; b < count; ++b) {
      const int t = mine[first + b];
      rows.write(basis, mesh.tets[t], elements.gradients[t], elements.volume[t], perTet[t], B.data() + 6 * b, ld);
    }
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, N, 6 * count, 1.0, B.data(), static_cast<int>(ld), 1.0,
                gram.data(), N);
    if (settings.progress) settings.progress(static_cast<int64_t>(first + count), static_cast<int64_t>(mine.size()));
  }
  EnergyPolynomial out;
  out.r = r;
  const std::vector<double> local = energyCoefficientsFromGram(gram.data(), N, r);
  out.coefficients.resize(local.size());
  MPI_Allreduce(local.data(), out.coefficients.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, comm);
  return out;
}

} // namespace quiver
