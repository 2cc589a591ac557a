// Full-space StVK force and tangent assembly on box meshes of growing size, single thread.
// Beside the tangent, the sparse product y = K x with the same K is timed in the same run as this
// machine's memory-bound yardstick: "x_spmv" says how many such passes one assembly costs.
//   build/release/bench/bench_fem_assembly --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <random>

#include "common/box_mesh.h"
#include "common/stvk_force_model.h"

using namespace quiver;

namespace {

struct Setup {
  TetMesh mesh;
  std::unique_ptr<StVKForceModel> model;
  Eigen::VectorXd u;

  explicit Setup(int cellsX) : mesh(makeBoxMesh({1, 0.25, 0.25}, {cellsX, cellsX / 4, cellsX / 4})) {
    Material m;
    model = std::make_unique<StVKForceModel>(mesh, std::vector<Material>(mesh.tets.size(), m));
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> d(-0.01, 0.01);
    u.resize(model->dofCount());
    for (auto& x : u) x = d(rng);
  }
};

void perTet(benchmark::State& state, const Setup& s) {
  state.counters["tets"] = s.mesh.tetCount();
  state.counters["tets/s"] = benchmark::Counter(double(s.mesh.tetCount()) * state.iterations(), benchmark::Counter::kIsRate);
}

void BM_InternalForce(benchmark::State& state) {
  Setup s(static_cast<int>(state.range(0)));
  Eigen::VectorXd f;
  for (auto _ : state) {
    s.model->internalForce(s.u, f);
    benchmark::DoNotOptimize(f.data());
  }
  perTet(state, s);
}

// Seconds per y = K x, the cheapest pass over K's memory, averaged over `repeats`.
double secondsPerMatVec(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& x, int repeats) {
  Eigen::VectorXd y(K.rows());
  auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < repeats; ++i) {
    y.noalias() = K * x;
    benchmark::DoNotOptimize(y.data());
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / repeats;
}

void BM_TangentRefill(benchmark::State& state) {
  Setup s(static_cast<int>(state.range(0)));
  Eigen::SparseMatrix<double> K = s.model->tangentStiffness(s.u);
  auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    s.model->tangentStiffness(s.u, K);
    benchmark::DoNotOptimize(K.valuePtr());
  }
  const double perRefill = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
                           static_cast<double>(state.iterations());
  perTet(state, s);
  state.counters["nnz"] = K.nonZeros();
  state.counters["x_spmv"] = perRefill / secondsPerMatVec(K, s.u, 20 + static_cast<int>(state.iterations()));
}

} // namespace

BENCHMARK(BM_InternalForce)->Arg(16)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TangentRefill)->Arg(16)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
