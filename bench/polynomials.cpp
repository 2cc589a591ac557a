// Benchmark of the bake's "polynomials" stage (computeEnergyPolynomial): the exact reduced StVK
// energy as a quartic in q, one blocked dsyrk over the tets. Run under mpirun; prints one CSV line
// per r (rank 0):
//
//   mesh,tets,r,ranks,threads,seconds,us_per_tet,tets_r4_per_s,gflops,dgemm_peak_gflops_per_rank,fraction_of_peak
//
//   mpirun -n 2 bench_polynomials MESH [--r 10,20,30,40] [--threads 1] [--repeat 3] [--min-time 0.5] [--no-header]
//
// --threads: the stage's threads per rank (PolynomialSettings::threads; quiver-bake's --threads).
//
// The stage's cost does not depend on the constraints or on the basis values, so the basis is a
// random 3n x r matrix with a fixed seed (the same on every rank). Each r is timed between MPI
// barriers (the slowest rank), best of --repeat runs or of as many as fill --min-time seconds.
//
// FLOPs counted: the dsyrk's only, which dominates. With N = r + r(r+1)/2 columns and K = 6 tets
// rows over all ranks, each of the upper triangle's N(N+1)/2 entries takes 2K flops: K N (N+1).
// The per-tet row building (G_j, the products G_j^T G_k, the 6x6 factor times [L S]; about 54k
// flops per tet at r = 30, 3.6% of the dsyrk's 1.47M) is not counted.
//
// Peak: single-thread cblas_dgemm on 1536 x 1536 matrices, on every rank at the same time (as the
// stage runs), best of 5 before the first r and after each r; each r reports the best so far,
// averaged over ranks; the fraction of peak is over ranks times threads such peaks (one per core
// at work: the DGEMM peak of one core). A comment line per r gives the time of the stage's dsyrk calls alone (same
// shapes, rows filled once): how much of the stage is BLAS and how much the row building, and the
// time of the call with no tets on any rank (what every call costs, whatever the mesh).
//
// BakeContext initialises MPI/PETSc as quiver-bake does and sets OpenBLAS to one thread per rank
// (checked below: a warning if not).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <cblas.h>
#include <mpi.h>

#include "common/material.h"
#include "common/tet_mesh.h"
#include "formats/mesh/read_mesh.h"
#include "precompute/bake_context.h"
#include "precompute/blas_core.h"
#include "precompute/stages/partition.h"
#include "precompute/stages/polynomials.h"

namespace {

struct Options {
  std::string mesh;
  std::vector<int> r{10, 20, 30, 40};
  int repeat = 3;
  double minTime = 0.5;
  int peakSize = 1536;
  int threads = 1;
  bool header = true;
};

const char* const kUsage =
    "usage: bench_polynomials MESH [--r 10,20,30,40] [--threads 1] [--repeat 3] [--min-time 0.5] [--peak-size 1536] "
    "[--no-header]\n";

std::vector<int> parseList(const std::string& text) {
  std::vector<int> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const int v = std::stoi(item);
    if (v < 1) throw std::invalid_argument("r must be at least 1");
    out.push_back(v);
  }
  if (out.empty()) throw std::invalid_argument("empty list of r");
  return out;
}

Options parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--r") o.r = parseList(value());
    else if (a == "--repeat") o.repeat = std::max(1, std::stoi(value()));
    else if (a == "--min-time") o.minTime = std::stod(value());
    else if (a == "--peak-size") o.peakSize = std::max(64, std::stoi(value()));
    else if (a == "--threads") o.threads = std::max(1, std::stoi(value()));
    else if (a == "--no-header") o.header = false;
    else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
    else if (o.mesh.empty()) o.mesh = a;
    else throw std::invalid_argument("more than one mesh given");
  }
  if (o.mesh.empty()) throw std::invalid_argument("no mesh given");
  return o;
}

// Single-thread DGEMM rate (GFLOP/s) of this rank, all ranks running at once: best of `runs`
// after one warm-up call.
double dgemmPeak(MPI_Comm comm, int n, int runs) {
  std::vector<double> A(static_cast<size_t>(n) * n), B(A.size()), C(A.size(), 0.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (size_t i = 0; i < A.size(); ++i) {
    A[i] = u(rng);
    B[i] = u(rng);
  }
  double best = 1e300;
  for (int k = 0; k <= runs; ++k) {
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, n, n, 1.0, A.data(), n, B.data(), n, 0.0, C.data(), n);
    const double t = MPI_Wtime() - t0;
    if (k > 0) best = std::min(best, t);
  }
  return 2.0 * n * n * static_cast<double>(n) / best * 1e-9;
}

// The stage's dsyrk calls alone (same shapes: blocks of `block` tets, 6 rows each, this rank's
// tets) on rows filled once: the BLAS part of the stage's time, without the row building.
class DsyrkAlone {
public:
  DsyrkAlone(int64_t tets, int N, int block)
      : tets_(tets), N_(N), block_(block), B_(6 * static_cast<size_t>(block) * N), gram_(static_cast<size_t>(N) * N) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double& b : B_) b = u(rng);
  }
  void operator()() {
    for (int64_t first = 0; first < tets_; first += block_) {
      const int count = static_cast<int>(std::min<int64_t>(block_, tets_ - first));
      cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, N_, 6 * count, 1.0, B_.data(), N_, 1.0, gram_.data(), N_);
    }
  }

private:
  int64_t tets_;
  int N_, block_;
  std::vector<double> B_, gram_;
};

// Best (smallest) time of `work` between barriers, the slowest rank's each time: at least
// --repeat runs, more until --min-time seconds have been spent (short runs are easily disturbed
// by other processes), at most 1000. Collective: every rank sees the same times and stops alike.
template <class Work>
double bestOf(MPI_Comm comm, const Options& o, Work work) {
  double best = 1e300, spent = 0;
  for (int k = 0; k < 1000 && (k < o.repeat || spent < o.minTime); ++k) {
    MPI_Barrier(comm);
    const double t0 = MPI_Wtime();
    work();
    MPI_Barrier(comm);
    double t = MPI_Wtime() - t0, slowest = 0;
    MPI_Allreduce(&t, &slowest, 1, MPI_DOUBLE, MPI_MAX, comm);
    best = std::min(best, slowest);
    spent += slowest;
  }
  return best;
}

std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

int run(const quiver::BakeContext& ctx, const Options& o) {
  const MPI_Comm comm = ctx.comm();
  const int ranks = ctx.size();
  if (ctx.rank() == 0 && openblas_get_num_threads() != 1)
    std::fprintf(stderr, "bench_polynomials: warning: OpenBLAS uses %d threads per rank, not 1\n",
                 openblas_get_num_threads());

  const quiver::CheckedMesh checked = quiver::loadMesh(o.mesh);
  const quiver::TetMesh& mesh = checked.mesh;
  const std::vector<quiver::Material> perTet = quiver::resolveTetMaterials(mesh, quiver::Material{});
  const quiver::Partition partition = quiver::partitionMesh(mesh, {ranks});
  const int64_t tets = mesh.tetCount();
  int64_t mine = std::count(partition.tetPart.begin(), partition.tetPart.end(), ctx.rank()), mostTets = 0;
  MPI_Allreduce(&mine, &mostTets, 1, MPI_INT64_T, MPI_MAX, comm);

  const int rMax = *std::max_element(o.r.begin(), o.r.end());
  Eigen::MatrixXd U(3 * static_cast<Eigen::Index>(mesh.vertexCount()), rMax);
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Eigen::Index j = 0; j < U.cols(); ++j)
    for (Eigen::Index i = 0; i < U.rows(); ++i) U(i, j) = uniform(rng);

  if (ctx.rank() == 0) {
    std::printf("# OpenBLAS %s, core %s, %d thread(s) per call; %d rank(s) of %d stage thread(s), at most %lld of "
                "%lld tets on one rank\n",
                openblas_get_config(), openblas_get_corename(), openblas_get_num_threads(), ranks, o.threads,
                static_cast<long long>(mostTets), static_cast<long long>(tets));
    if (o.header)
      std::printf("mesh,tets,r,ranks,threads,seconds,us_per_tet,tets_r4_per_s,gflops,dgemm_peak_gflops_per_rank,"
                  "fraction_of_peak\n");
    std::fflush(stdout);
  }

  // A rank's DGEMM rate can only be lowered by disturbances, so each r reports the best seen so far
  // in this run (one measurement before the first r, one after each).
  double peak = dgemmPeak(comm, o.peakSize, 5);
  for (const int r : o.r) {
    const Eigen::MatrixXd basis = U.leftCols(r);
    quiver::PolynomialSettings settings;
    settings.threads = o.threads;
    size_t coefficients = 0;
    const double best = bestOf(comm, o, [&] {
      coefficients = quiver::computeEnergyPolynomial(comm, mesh, perTet, partition.tetPart, basis, settings)
                         .coefficients.size();
    });
    // What every call costs however few tets a rank has: the same call with no tets on any rank.
    const std::vector<int> nobody(partition.tetPart.size(), -1);
    const double fixed = bestOf(comm, o, [&] {
      quiver::computeEnergyPolynomial(comm, mesh, perTet, nobody, basis, settings);
    });
    const int N = r + r * (r + 1) / 2;
    DsyrkAlone dsyrk(mine, N, settings.tetsPerBlock);
    const double blas = bestOf(comm, o, [&] { dsyrk(); });
    peak = std::max(peak, dgemmPeak(comm, o.peakSize, 5));
    double peakSum = 0;
    MPI_Allreduce(&peak, &peakSum, 1, MPI_DOUBLE, MPI_SUM, comm);
    const double peakPerRank = peakSum / ranks;

    const double flops = 6.0 * static_cast<double>(tets) * N * (N + 1.0);
    const double gflops = flops / best * 1e-9;
    const double r4 = static_cast<double>(r) * r * r * r;
    if (ctx.rank() == 0) {
      std::printf("%s,%lld,%d,%d,%d,%.6f,%.3f,%.4e,%.2f,%.2f,%.3f\n", baseName(o.mesh).c_str(),
                  static_cast<long long>(tets), r, ranks, o.threads, best, 1e6 * best / static_cast<double>(tets),
                  static_cast<double>(tets) * r4 / best, gflops, peakPerRank,
                  gflops / (ranks * std::min(o.threads, quiver::gramSlices(N, mine)) * peakPerRank));
      std::printf("# r = %d: %zu coefficients; dsyrk alone %.6f s (%.3f of the stage); no tets %.6f s\n", r,
                  coefficients, blas, blas / best, fixed);
      std::fflush(stdout);
    }
  }
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  quiver::chooseBlasCore(argv);  // the kernels the bake would run on (the "# OpenBLAS" line names them)
  Options options;
  try {
    options = parseOptions(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_polynomials: %s\n%s", e.what(), kUsage);
    return 2;
  }
  try {
    quiver::BakeContext ctx({argv[0]});
    try {
      return run(ctx, options);
    } catch (const std::exception& e) {
      // Every rank reads the same mesh, so failures there are the same on every rank; anything
      // else ends the job rather than leave a rank waiting in a collective.
      std::fprintf(stderr, "bench_polynomials: rank %d: %s\n", ctx.rank(), e.what());
      MPI_Abort(ctx.comm(), 1);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_polynomials: %s\n", e.what());
  }
  return 1;
}
