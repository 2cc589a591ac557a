// The runtime's hot paths on baked models, single thread (Google Benchmark):
//   Evaluate/force, Evaluate/force+stiffness, Step/newton (implicit Newmark, Barbic & James's one
//   Newton iteration), Step/minimize (the default solver), both under a load that keeps the object
//   moving, and ManyObjects: 1000 instances of one model stepped per frame (both solvers, one by one
//   and in one qv_instances_step call).
// Peak FMA throughput of this core is measured in the same run (PeakFma) so that the evaluation
// can be reported as a fraction of it. Each benchmark's label carries a hash of its final state.
//   bench/runtime.py --build build/release     (bakes the models, runs this, prints the table)
//   build/release/bench/bench_runtime MODEL.qvr [MODEL.qvr ...] [--benchmark_* flags]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "formats/model/fnv1a.h"
#include "formats/model/qvr.h"
#include "quiver/quiver.h"

namespace {

std::string stateHash(const qv_instance* s, int r) {
  std::vector<double> q(3 * static_cast<size_t>(r));
  qv_instance_get_state(s, q.data(), q.data() + r, q.data() + 2 * r);
  char text[20];
  std::snprintf(text, sizeof text, "%016llx",
                static_cast<unsigned long long>(quiver::fnv1a64(q.data(), q.size() * sizeof(double))));
  return text;
}

// Floating-point operations of one evaluation, as the code performs them: the packed symmetric
// product (2 multiply-adds per stored coefficient, about P(P+1)/2 of them), the cubic axpys
// (r P multiply-adds) and the per-pair assembly (about 10 P).
double evaluationFlops(int r) {
  const double P = r * (r + 1) / 2.0;
  return 4 * P * (P + 1) / 2 + 2 * r * P + 10 * P;
}

struct Loaded {
  qv_model* model = nullptr;
  qv_model_info info{};
  explicit Loaded(const char* path) {
    char message[512];
    if (qv_model_load_file(path, nullptr, nullptr, &model, message, sizeof message) != QV_OK) {
      std::fprintf(stderr, "%s\n", message);
      std::exit(1);
    }
    qv_model_get_info(model, &info);
  }
};

// 12 independent fused multiply-add chains of 8 doubles: what one core can sustain.
typedef double v8 __attribute__((vector_size(64)));
__attribute__((target("avx512f,fma"), noinline)) double fmaChains(long iterations) {
  v8 acc[12];
  const v8 a = {1.0000001, 1.0000001, 1.0000001, 1.0000001, 1.0000001, 1.0000001, 1.0000001, 1.0000001};
  const v8 b = {1e-9, 1e-9, 1e-9, 1e-9, 1e-9, 1e-9, 1e-9, 1e-9};
  for (int i = 0; i < 12; ++i) acc[i] = b * (1.0 + i);  // distinct chains: none can be merged
  for (long i = 0; i < iterations; ++i)
    for (auto& x : acc) x = x * a + b;
  double sum = 0;
  for (auto& x : acc)
    for (int k = 0; k < 8; ++k) sum += x[k];
  return sum;
}

void PeakFma(benchmark::State& state) {
  const long iterations = 1 << 20;
  for (auto _ : state) {
    long n = iterations;
    benchmark::DoNotOptimize(n);  // an opaque argument: the (pure) call cannot be hoisted out of the loop
    benchmark::DoNotOptimize(fmaChains(n));
  }
  state.counters["GFLOPS"] = benchmark::Counter(2.0 * 8 * 12 * iterations * state.iterations(),
                                                benchmark::Counter::kIsRate, benchmark::Counter::kIs1000);
}

void Evaluate(benchmark::State& state, const char* path, bool withStiffness) {
  Loaded m(path);
  const int r = m.info.r;
  std::vector<double> q(r), force(r), K(static_cast<size_t>(r) * r), scratch(qv_model_scratch_size(m.model) / 8 + 1);
  for (int i = 0; i < r; ++i) q[i] = 1e-3 * (i + 1);
  for (auto _ : state) {
    qv_model_evaluate(m.model, q.data(), nullptr, force.data(), withStiffness ? K.data() : nullptr, scratch.data());
    benchmark::DoNotOptimize(force.data());
    q[0] += 1e-12;
  }
  state.counters["r"] = r;
  state.counters["GFLOPS"] = benchmark::Counter(evaluationFlops(r) * state.iterations(), benchmark::Counter::kIsRate,
                                                benchmark::Counter::kIs1000);
  qv_model_destroy(m.model);
}

// Gravity, plus twice its pull on the first coordinate flipping every half second, so that every
// step has work to do (a settled object converges at once and would flatter the solver).
void Step(benchmark::State& state, const char* path, qv_solver solver) {
  Loaded m(path);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.solver = solver;
  if (solver == QV_SOLVER_NEWTON) config.newton_iterations = 1;
  qv_instance* s = nullptr;
  qv_instance_create(m.model, &config, nullptr, &s);
  const double g[3] = {0, 0, -QV_STANDARD_GRAVITY};
  qv_instance_set_gravity(s, g);
  std::vector<double> push(m.info.r, 0.0);
  const double amplitude = 2 * QV_STANDARD_GRAVITY * std::fabs(qv_model_gravity(m.model)[2 * m.info.r]);
  long steps = 0, iterations = 0;
  for (auto _ : state) {
    push[0] = (steps / 30) % 2 ? amplitude : -amplitude;
    qv_instance_add_reduced_force(s, push.data());
    qv_instance_step(s);
    qv_step_report report;
    qv_instance_last_step(s, &report);
    iterations += report.newton_iterations;
    ++steps;
  }
  state.counters["r"] = m.info.r;
  state.counters["newton_per_step"] = static_cast<double>(iterations) / static_cast<double>(steps);
  state.SetLabel("state " + stateHash(s, m.info.r));
  qv_instance_destroy(s);
  qv_model_destroy(m.model);
}

// `objects` instances of one model per frame, each under its own push on the first coordinate (0.1
// to 0.2 times what gravity puts there, flipping every half second, out of phase from one instance
// to the next: about 0.1 to 0.3 m at the tip of the 1 m bar), stepped one
// by one (qv_instance_step) or in one call (qv_instances_step: groups of 8 evaluated together).
void ManyObjects(benchmark::State& state, const char* path, qv_solver solver, bool together) {
  Loaded m(path);
  const int objects = static_cast<int>(state.range(0)), r = m.info.r;
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.solver = solver;
  if (solver == QV_SOLVER_NEWTON) config.newton_iterations = 1;
  std::vector<qv_instance*> all(objects);
  for (auto& s : all) qv_instance_create(m.model, &config, nullptr, &s);
  const size_t bytes = qv_instances_step_scratch_size(m.model, 1);
  void* scratch = std::aligned_alloc(64, (bytes + 63) / 64 * 64);
  const double amplitude = 0.1 * QV_STANDARD_GRAVITY * std::fabs(qv_model_gravity(m.model)[2 * r]);
  std::vector<double> push(r, 0.0);
  std::vector<qv_step_status> statuses(objects);
  long frame = 0, resets = 0;
  for (auto _ : state) {
    for (int i = 0; i < objects; ++i) {
      push[0] = (1 + (i % 11) / 10.0) * (((frame + i) / 30) % 2 ? amplitude : -amplitude);
      qv_instance_add_reduced_force(all[i], push.data());
    }
    if (together) {
      qv_instances_step(all.data(), objects, nullptr, scratch, bytes, statuses.data());
      for (qv_step_status status : statuses) resets += status == QV_STEP_RESET;
    } else {
      for (auto* s : all) resets += qv_instance_step(s) == QV_STEP_RESET;
    }
    ++frame;
  }
  state.counters["r"] = r;
  state.counters["frame_ms"] = benchmark::Counter(1e3 * state.iterations(), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["resets"] = static_cast<double>(resets);  // expected 0: a reset step is no measure
  state.SetLabel("state " + stateHash(all.back(), r));
  std::free(scratch);
  for (auto* s : all) qv_instance_destroy(s);
  qv_model_destroy(m.model);
}

} // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (__builtin_cpu_supports("avx512f")) benchmark::RegisterBenchmark("PeakFma", PeakFma);
  for (int i = 1; i < argc; ++i) {
    const char* path = argv[i];
    Loaded probe(path);
    const std::string r = "/r" + std::to_string(probe.info.r);
    qv_model_destroy(probe.model);
    benchmark::RegisterBenchmark(("Evaluate/force" + r).c_str(), Evaluate, path, false)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Evaluate/force+stiffness" + r).c_str(), Evaluate, path, true)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Step/newton" + r).c_str(), Step, path, QV_SOLVER_NEWTON)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Step/minimize" + r).c_str(), Step, path, QV_SOLVER_MINIMIZE)->Unit(benchmark::kMicrosecond);
    if (probe.info.r == 20 || probe.info.r == 30)
      for (qv_solver solver : {QV_SOLVER_NEWTON, QV_SOLVER_MINIMIZE})
        for (bool together : {false, true})
          benchmark::RegisterBenchmark(("ManyObjects/" + std::string(qv_solver_name(solver)) +
                                        (together ? "/together" : "/one-by-one") + r).c_str(),
                                       ManyObjects, path, solver, together)
              ->Arg(1000)
              ->Unit(benchmark::kMillisecond);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
