// The runtime's hot paths on baked models, single thread (Google Benchmark):
//   Evaluate/force, Evaluate/force+stiffness (float64 and float32 coefficients), EvaluateGroup
//   (sixteen states at once, as qv_instances_step evaluates them; both precisions), Step/newton
//   (implicit Newmark, Barbic & James's one Newton iteration; both precisions), Step/minimize (the
//   default solver), both under a load that keeps the object moving, Flying/step (a free model's
//   instance in flight, spun and pushed, given as --flying=MODEL.qvr), and ManyObjects: 1000
//   instances of one model stepped per frame (both solvers, one by one and in one
//   qv_instances_step call).
// Measured in the same run, as yardsticks: this core's peak FMA throughput (PeakFma) and a plain
// read of as many bytes as one evaluation streams (Stream/f64, Stream/f32: the floor set by
// wherever those bytes sit). Each benchmark's label carries a hash of its final state.
//   bench/runtime.py --build build/release     (bakes the models, runs this, prints the table)
//   build/release/bench/bench_runtime MODEL.qvr [MODEL.qvr ...] [--flying=FREE.qvr] [--benchmark_* flags]
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
#include "runtime/src/model.h"
#include "runtime/src/reduced_polynomial.h"

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

// The same for a group of ReducedPolynomial::kLanes states (evaluateLanes): the quartic's two
// passes (C(r+2,3) r and P r multiply-adds per state), the cubic's (P r) and the per-pair
// assembly.
double groupFlops(int r) {
  const double P = r * (r + 1) / 2.0, T = r * (r + 1) * (r + 2) / 6.0;
  return quiver::rt::ReducedPolynomial::kLanes * (2 * r * (T + 2 * P) + 10 * P);
}

struct Loaded {
  qv_model* model = nullptr;
  qv_model_info info{};
  // groupLayout: qv_model_config.group_layout (-1, the default: as the runtime decides).
  explicit Loaded(const char* path, int precision = 64, int groupLayout = -1) {
    char message[512];
    qv_model_config config;
    qv_model_config_init(&config);
    config.coefficient_precision = precision;
    config.group_layout = groupLayout;
    if (qv_model_load_file(path, &config, nullptr, &model, message, sizeof message) != QV_OK) {
      std::fprintf(stderr, "%s\n", message);
      std::exit(1);
    }
    qv_model_get_info(model, &info);
  }
};

// 12 independent fused multiply-add chains of W doubles: what one core can sustain, with the
// widest vectors it has (AVX-512: W = 8, AVX2: W = 4).
typedef double v8 __attribute__((vector_size(64)));
typedef double v4 __attribute__((vector_size(32)));
template <class vec, int W>
__attribute__((always_inline)) inline double fmaChains(long iterations) {  // compiled in its callers' targets
  vec acc[12], a, b;
  for (int k = 0; k < W; ++k) a[k] = 1.0000001, b[k] = 1e-9;
  for (int i = 0; i < 12; ++i) acc[i] = b * (1.0 + i);  // distinct chains: none can be merged
  for (long i = 0; i < iterations; ++i)
    for (auto& x : acc) x = x * a + b;
  double sum = 0;
  for (auto& x : acc)
    for (int k = 0; k < W; ++k) sum += x[k];
  return sum;
}
__attribute__((target("avx512f,fma"), noinline)) double fmaChains512(long n) { return fmaChains<v8, 8>(n); }
__attribute__((target("avx2,fma"), noinline)) double fmaChains256(long n) { return fmaChains<v4, 4>(n); }

void PeakFma(benchmark::State& state, int width) {
  const long iterations = 1 << 20;
  for (auto _ : state) {
    long n = iterations;
    benchmark::DoNotOptimize(n);  // an opaque argument: the (pure) call cannot be hoisted out of the loop
    benchmark::DoNotOptimize(width == 8 ? fmaChains512(n) : fmaChains256(n));
  }
  state.counters["GFLOPS"] = benchmark::Counter(2.0 * width * 12 * iterations * state.iterations(),
                                                benchmark::Counter::kIsRate, benchmark::Counter::kIs1000);
}

// Reads `bytes` (the coefficients one evaluation streams) as doubles into eight running sums of
// the widest vectors this core has: the floor an evaluation of that many bytes meets where they
// sit (L1, L2, L3 or memory), in the same run. The buffer is read again and again, as the
// evaluation reads its coefficients. Until 2026-11-28 this read was plain scalar code, which GCC
// compiled to SSE2 (16-byte loads into four sums): below L2's bandwidth, so the floor was too high
// for whatever fits in L2 (0.57 MB at r = 30, float32: 6.0 us, against 3.2-3.3 us for this read).
template <class vec, int W>
__attribute__((always_inline)) inline double streamChains(const double* x, size_t n) {  // in its callers' targets
  vec acc[8] = {};
  size_t i = 0;
  for (; i + 8 * W <= n; i += 8 * W)
    for (int k = 0; k < 8; ++k) {
      vec v;
      std::memcpy(&v, x + i + k * W, sizeof v);
      acc[k] += v;
    }
  double sum = 0;
  for (; i < n; ++i) sum += x[i];
  for (auto& a : acc)
    for (int k = 0; k < W; ++k) sum += a[k];
  return sum;
}
__attribute__((target("avx512f"), noinline)) double stream512(const double* x, size_t n) {
  return streamChains<v8, 8>(x, n);
}
__attribute__((target("avx2"), noinline)) double stream256(const double* x, size_t n) { return streamChains<v4, 4>(x, n); }
typedef double v2 __attribute__((vector_size(16)));
__attribute__((noinline)) double stream128(const double* x, size_t n) { return streamChains<v2, 2>(x, n); }

void Stream(benchmark::State& state, size_t bytes) {
  std::vector<double> buffer(bytes / sizeof(double), 1.0);
  double (*read)(const double*, size_t) = __builtin_cpu_supports("avx512f") ? stream512
                                           : __builtin_cpu_supports("avx2")  ? stream256
                                                                             : stream128;
  for (auto _ : state) benchmark::DoNotOptimize(read(buffer.data(), buffer.size()));
  state.counters["bytes"] = static_cast<double>(bytes);
  state.counters["GBps"] = benchmark::Counter(static_cast<double>(bytes) * state.iterations(), benchmark::Counter::kIsRate,
                                              benchmark::Counter::kIs1000);
}

// What is asked of the evaluation: the force, the force and the stiffness, or the energy alone (the
// energy budgets' checks: summed from the monomials).
enum class Asked { force, forceAndStiffness, energy };

void Evaluate(benchmark::State& state, const char* path, Asked asked, int precision) {
  Loaded m(path, precision);
  const int r = m.info.r;
  std::vector<double> q(r), force(r), K(static_cast<size_t>(r) * r), scratch(qv_model_scratch_size(m.model) / 8 + 1);
  for (int i = 0; i < r; ++i) q[i] = 1e-3 * (i + 1);
  double energy = 0;
  for (auto _ : state) {
    if (asked == Asked::energy)
      qv_model_evaluate(m.model, q.data(), &energy, nullptr, nullptr, scratch.data());
    else
      qv_model_evaluate(m.model, q.data(), nullptr, force.data(), asked == Asked::forceAndStiffness ? K.data() : nullptr,
                        scratch.data());
    benchmark::DoNotOptimize(force.data());
    benchmark::DoNotOptimize(energy);
    q[0] += 1e-12;
  }
  state.counters["r"] = r;
  if (asked != Asked::energy)
    state.counters["GFLOPS"] = benchmark::Counter(evaluationFlops(r) * state.iterations(), benchmark::Counter::kIsRate,
                                                  benchmark::Counter::kIs1000);
  qv_model_destroy(m.model);
}

// One evaluation of force, energy and stiffness for a group of kLanes states at once, as
// qv_instances_step evaluates them (the arithmetic, not the coefficients' bytes, bounds it:
// compare GFLOPS with PeakFma's).
void EvaluateGroup(benchmark::State& state, const char* path, int precision) {
  using quiver::rt::ReducedPolynomial;
  Loaded m(path, precision, 1);
  const int r = m.info.r, L = ReducedPolynomial::kLanes;
  const size_t P = static_cast<size_t>(r) * (r + 1) / 2;
  std::vector<double> q(static_cast<size_t>(r) * L), force(q.size()), energy(L), K(P * L);
  double* scratch = static_cast<double*>(std::aligned_alloc(64, (ReducedPolynomial::laneScratchSize(r) * 8 + 63) / 64 * 64));
  const double* at[L];
  double* f[L];
  for (int l = 0; l < L; ++l) {
    for (int i = 0; i < r; ++i) q[l * r + i] = 1e-3 * (i + 1 + l);
    at[l] = q.data() + l * r;
    f[l] = force.data() + l * r;
  }
  for (auto _ : state) {
    m.model->polynomial.evaluateLanes(at, L, energy.data(), f, K.data(), scratch);
    benchmark::DoNotOptimize(K.data());
    q[0] += 1e-12;
  }
  state.counters["r"] = r;
  state.counters["states"] = L;
  state.counters["GFLOPS"] =
      benchmark::Counter(groupFlops(r) * state.iterations(), benchmark::Counter::kIsRate, benchmark::Counter::kIs1000);
  std::free(scratch);
  qv_model_destroy(m.model);
}

// A tenth of gravity's pull on the first coordinate, flipping every quarter second (ManyObjects'
// load), so that every step has work to do (a settled object converges at once and would flatter
// the minimiser), within the strains one fixed Newton iteration can follow. Until 0.9.0 gravity was
// added: this soft bar (E = 1 MPa) would sag by 1.5 times its length under it by linear theory, and
// once the default solver stopped over-damping the swing, one fixed Newton iteration failed every
// other step (the minimiser took 59% of them at r = 30: `minimized`), so the column no longer timed
// a fixed Newton step.
void Step(benchmark::State& state, const char* path, qv_solver solver, int precision) {
  Loaded m(path, precision);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.solver = solver;
  if (solver == QV_SOLVER_NEWTON) config.newton_iterations = 1;
  qv_instance* s = nullptr;
  qv_instance_create(m.model, &config, nullptr, &s);
  std::vector<double> push(m.info.r, 0.0);
  const double amplitude = 0.1 * QV_STANDARD_GRAVITY * std::fabs(qv_model_gravity(m.model)[2 * m.info.r]);
  long steps = 0, iterations = 0, minimized = 0;
  for (auto _ : state) {
    push[0] = (steps / 15) % 2 ? amplitude : -amplitude;
    qv_instance_add_reduced_force(s, push.data());
    qv_instance_step(s);
    qv_step_report report;
    qv_instance_last_step(s, &report);
    iterations += report.newton_iterations;
    minimized += report.minimized;
    ++steps;
  }
  state.counters["r"] = m.info.r;
  state.counters["newton_per_step"] = static_cast<double>(iterations) / static_cast<double>(steps);
  state.counters["minimized"] = static_cast<double>(minimized) / static_cast<double>(steps);
  state.SetLabel("state " + stateHash(s, m.info.r));
  qv_instance_destroy(s);
  qv_model_destroy(m.model);
}

// A free model's instance pushed on one corner vertex (0.1 times its weight, flipping every quarter
// second). In flight (config.free_flight), spun at (0, 3, 10) rad/s, the frame turns, tumbles and
// deforms: the step with its rigid frame (rigid_frame.h), the centrifugal potential in every
// evaluation. The push's torque changes the spin at every step, so the turns' settlement
// (qv_instance::takeOutTurnExcess, a second refresh) does not run here. Unmoved: the same push on
// the model without flight (its frame stays put).
void FlyingStep(benchmark::State& state, const char* path, bool flying) {
  Loaded m(path);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.free_flight = flying;
  qv_instance* s = nullptr;
  qv_instance_create(m.model, &config, nullptr, &s);
  const qv_rigid_state spin = {{0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0}, {0, 3, 10}};
  if (flying) qv_instance_set_rigid_state(s, &spin);
  const double push = 0.1 * QV_STANDARD_GRAVITY * m.info.total_mass;
  long steps = 0, iterations = 0, resets = 0;
  for (auto _ : state) {
    const double force[3] = {0, 0, (steps / 15) % 2 ? push : -push};
    qv_instance_add_vertex_force(s, 0, force);
    resets += qv_instance_step(s) == QV_STEP_RESET;
    qv_step_report report;
    qv_instance_last_step(s, &report);
    iterations += report.newton_iterations;
    ++steps;
  }
  state.counters["r"] = m.info.r;
  state.counters["newton_per_step"] = static_cast<double>(iterations) / static_cast<double>(steps);
  state.counters["resets"] = static_cast<double>(resets);  // expected 0: a reset step is no measure
  state.SetLabel("state " + stateHash(s, m.info.r));
  qv_instance_destroy(s);
  qv_model_destroy(m.model);
}

// `objects` instances of one model per frame, each under its own push on the first coordinate (0.1
// to 0.2 times what gravity puts there, flipping every quarter second, out of phase from one
// instance to the next: the load of Step, spread), stepped one by one (qv_instance_step) or in one call
// (qv_instances_step: groups of 16 evaluated together).
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
  long frame = 0, resets = 0, minimized = 0;
  for (auto _ : state) {
    for (int i = 0; i < objects; ++i) {
      push[0] = (1 + (i % 11) / 10.0) * (((frame + i) / 15) % 2 ? amplitude : -amplitude);
      qv_instance_add_reduced_force(all[i], push.data());
    }
    if (together) {
      qv_instances_step(all.data(), objects, nullptr, scratch, bytes, statuses.data());
      for (qv_step_status status : statuses) resets += status == QV_STEP_RESET;
    } else {
      for (auto* s : all) resets += qv_instance_step(s) == QV_STEP_RESET;
    }
    for (auto* s : all) {
      qv_step_report report;
      qv_instance_last_step(s, &report);
      minimized += report.minimized;
    }
    ++frame;
  }
  state.counters["r"] = r;
  state.counters["resets"] = static_cast<double>(resets);  // expected 0: a reset step is no measure
  state.counters["minimized"] = static_cast<double>(minimized);  // fixed Newton steps the minimiser took
  state.SetLabel("state " + stateHash(all.back(), r));
  std::free(scratch);
  for (auto* s : all) qv_instance_destroy(s);
  qv_model_destroy(m.model);
}

} // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (__builtin_cpu_supports("avx512f"))
    benchmark::RegisterBenchmark("PeakFma", PeakFma, 8);
  else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    benchmark::RegisterBenchmark("PeakFma", PeakFma, 4);
  for (int i = 1; i < argc; ++i) {
    const char* path = argv[i];
    if (std::strncmp(path, "--flying=", 9) == 0) {  // a free model: its step in flight and without
      Loaded probe(path + 9);
      const std::string r = "/r" + std::to_string(probe.info.r);
      qv_model_destroy(probe.model);
      benchmark::RegisterBenchmark(("Flying/step" + r).c_str(), FlyingStep, path + 9, true)->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("Flying/unmoved" + r).c_str(), FlyingStep, path + 9, false)->Unit(benchmark::kMicrosecond);
      continue;
    }
    Loaded probe(path);
    const std::string r = "/r" + std::to_string(probe.info.r);
    qv_model_destroy(probe.model);
    benchmark::RegisterBenchmark(("Evaluate/force" + r).c_str(), Evaluate, path, Asked::force, 64)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Evaluate/force+stiffness" + r).c_str(), Evaluate, path, Asked::forceAndStiffness, 64)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Evaluate/force+stiffness/f32" + r).c_str(), Evaluate, path, Asked::forceAndStiffness, 32)
        ->Unit(benchmark::kMicrosecond);
    for (int precision : {64, 32})
      benchmark::RegisterBenchmark(("EvaluateGroup" + std::string(precision == 32 ? "/f32" : "") + r).c_str(),
                                   EvaluateGroup, path, precision)
          ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Evaluate/energy" + r).c_str(), Evaluate, path, Asked::energy, 64)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Step/newton" + r).c_str(), Step, path, QV_SOLVER_NEWTON, 64)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Step/newton/f32" + r).c_str(), Step, path, QV_SOLVER_NEWTON, 32)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Step/minimize" + r).c_str(), Step, path, QV_SOLVER_MINIMIZE, 64)->Unit(benchmark::kMicrosecond);
    for (bool single : {false, true})
      benchmark::RegisterBenchmark(("Stream/" + std::string(single ? "f32" : "f64") + r).c_str(), Stream,
                                   quiver::rt::ReducedPolynomial::evaluationBytes(probe.info.r, single))
          ->Unit(benchmark::kMicrosecond);
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
