#include "precompute/stages/polynomials.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <system_error>
#include <thread>

#include <cblas.h>

#include "common/reduced_energy.h"
#include "formats/model/qvr_writer.h"
#include "precompute/checkpoint.h"
#include "precompute/input_hash.h"

namespace quiver {

int gramSlices(int N, size_t tets) {
  const double gramBytes = 8.0 * N * N;
  const int fitting = static_cast<int>(std::min(4.0, std::floor(double(1 << 30) / gramBytes)));
  return static_cast<int>(std::max<size_t>(1, std::min<size_t>(std::max(1, fitting), tets)));
}

EnergyPolynomial computeEnergyPolynomial(MPI_Comm comm, const TetMesh& mesh, const std::vector<Material>& perTet,
                                         const std::vector<int>& tetPart, const Eigen::MatrixXd& basis,
                                         const PolynomialSettings& settings) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const int r = static_cast<int>(basis.cols());
  std::vector<int> mine;
  for (int t = 0; t < mesh.tetCount(); ++t)
    if (tetPart[t] == rank) mine.push_back(t);
  const int N = ReducedEnergyRows::columns(r);
  const TetElements elements = computeTetElements(mesh);
  const int block = std::max(1, settings.tetsPerBlock);
  const int slices = gramSlices(N, mine.size());
  const int threads = std::clamp(settings.threads, 1, slices);
  std::vector<Eigen::MatrixXd> grams(slices);
  std::atomic<int64_t> done{0};
  // Slice `s`: tets [mine.size() s / slices, mine.size() (s + 1) / slices) of this rank's, in order.
  const auto sumSlice = [&](int s, bool reports) {
    const std::vector<int> tets(mine.begin() + static_cast<int64_t>(mine.size() * s / slices),
                                mine.begin() + static_cast<int64_t>(mine.size() * (s + 1) / slices));
    ReducedEnergyRows rows(basis, mesh, tets);
    // The block's rows B_e^T side by side: N x 6 block, column-major (each row of B_e one contiguous run).
    std::vector<double> B(6 * static_cast<size_t>(block) * N);
    Eigen::MatrixXd& gram = grams[s];
    gram.setZero(N, N);
    for (size_t first = 0; first < tets.size(); first += block) {
      const int count = static_cast<int>(std::min<size_t>(block, tets.size() - first));
      for (int b = 0; b < count; ++b) {
        const int t = tets[first + b];
        rows.write(mesh.tets[t], elements.gradients[t], elements.volume[t], perTet[t], B.data() + 6 * b * static_cast<int64_t>(N), N);
      }
      cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, N, 6 * count, 1.0, B.data(), N, 1.0, gram.data(), N);
      const int64_t total = done += count;
      if (reports && settings.progress) settings.progress(total, static_cast<int64_t>(mine.size()));
    }
  };
  // Each thread takes the next slice not yet taken until none is left; the calling thread is
  // thread 0, and reports. Where the system starts fewer threads than asked, those take more.
  std::vector<std::exception_ptr> failure(threads);
  std::atomic<int> next{0};
  const auto work = [&](int k) {
    try {
      for (int s; (s = next++) < slices;) sumSlice(s, k == 0);
    } catch (...) {
      failure[k] = std::current_exception();
    }
  };
  std::vector<std::thread> helpers;
  try {
    for (int k = 1; k < threads; ++k) helpers.emplace_back(work, k);
  } catch (const std::system_error&) {
  }
  work(0);
  for (std::thread& helper : helpers) helper.join();
  if (settings.progress) settings.progress(done, static_cast<int64_t>(mine.size()));  // whichever thread finished
  for (const std::exception_ptr& e : failure)
    if (e) std::rethrow_exception(e);
  for (int s = 1; s < slices; ++s) grams[0] += grams[s];
  EnergyPolynomial out;
  out.r = r;
  const std::vector<double> local = energyCoefficientsFromGram(grams[0].data(), N, r);
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

std::string describePolynomial(const EnergyPolynomial& energy, int tets, double seconds, int threads) {
  return std::to_string(energy.coefficients.size()) + " energy coefficients (exact, r = " + std::to_string(energy.r) +
         "), " + shortNumber(1e6 * seconds / tets) + " us per tet, " + std::to_string(threads) +
         (threads == 1 ? " thread" : " threads") + " per rank";
}

EnergyPolynomial polynomialStage(StageRunner& stages, const BakeContext& ctx, const TetMesh& mesh,
                                 const std::vector<Material>& perTet, const std::vector<int>& tetPart,
                                 const Eigen::MatrixXd& basis, const std::string& inputHash, int threads) {
  bool reused = false;
  const int N = ReducedEnergyRows::columns(static_cast<int>(basis.cols()));
  // No more threads than the rank's slices (the tets of rank 0, which the others' counts are near).
  threads = std::clamp(threads, 1, gramSlices(N, static_cast<size_t>(mesh.tetCount() / ctx.size())));
  const EnergyPolynomial energy = stages.checkpointed(
      "polynomials", "/polynomials", inputHash, [&](const Archive& a) { return readPolynomial(a); },
      [&] {
        ProgressMeter meter(ctx, "polynomials", "tets integrated (rank 0)");
        PolynomialSettings settings;
        settings.progress = meter.callback();
        settings.threads = threads;
        return computeEnergyPolynomial(ctx.comm(), mesh, perTet, tetPart, basis, settings);
      },
      [&](Archive& a, const EnergyPolynomial& e, const std::string& h) { writePolynomial(a, e, h); }, reused);
  stages.report(describePolynomial(energy, mesh.tetCount(), stages.last(), threads), reused);
  return energy;
}

} // namespace quiver
