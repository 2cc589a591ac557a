// Render output of a model with a render mesh (qv_instance_render), single thread, against the
// simulated vertices' output (qv_instance_positions) in the same run, per vertex:
//   build/release/bench/bench_render_output [--benchmark_* flags]
// The model is made here: a 20 x 10 x 10-cell box of 12000 tets (2541 vertices) with r = 30 random
// basis vectors, and 100000 render vertices at random points of it in Morton order (bound to their
// tets by common/embedding.h); issue 14 asks for <= 1 ms per frame for such a mesh.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "common/box_mesh.h"
#include "common/embedding.h"
#include "common/mesh_checks.h"
#include "formats/model_contents.h"
#include "quiver/quiver.h"

namespace {

constexpr int kR = 30, kRenderVertices = 100000;

struct Fixture {
  qv_model* model = nullptr;
  qv_instance* instance = nullptr;
  std::vector<float> positions, normals, simulated;
  std::vector<double> scratch;

  Fixture() {
    using namespace quiver;
    CheckedMesh mesh;
    mesh.mesh = makeBoxMesh({2.0, 1.0, 1.0}, {20, 10, 10});
    for (int v = 0; v < mesh.mesh.vertexCount(); ++v) mesh.fileVertex.push_back(v), mesh.loadedVertex.push_back(v);
    std::mt19937 random(1);
    std::uniform_real_distribution<double> u(0, 1);
    Eigen::MatrixXd basis(3 * mesh.mesh.vertexCount(), kR);
    for (Eigen::Index i = 0; i < basis.size(); ++i) basis.data()[i] = 1e-3 * (u(random) - 0.5);
    std::vector<double> energy(energyCoefficientCount(kR), 0.0), eigenvalues(kR, 1.0);
    for (int j = 0; j < kR; ++j) energy[monomialIndex2(kR, j, j)] = 0.5;  // E = |q|^2 / 2
    Material material;
    ModelContents c = makeModelContents(mesh, std::vector<Material>(mesh.mesh.tets.size(), material), basis, energy, eigenvalues,
                                        Eigen::MatrixXd::Zero(kR, 3), ExportSettings{});
    // Random points, then in Morton order: a real mesh lists neighbouring vertices near each other
    // (random order costs 2x: every gather a cache miss).
    std::vector<std::pair<uint64_t, std::array<float, 3>>> scattered;
    for (int i = 0; i < kRenderVertices; ++i) {
      const std::array<float, 3> p{float(2 * u(random)), float(u(random)), float(u(random))};
      uint64_t code = 0;
      for (int bit = 9; bit >= 0; --bit)
        for (int a = 0; a < 3; ++a) code = (code << 1) | ((static_cast<uint64_t>(p[a] / (a ? 1.0f : 2.0f) * 1023) >> bit) & 1);
      scattered.push_back({code, p});
    }
    std::sort(scattered.begin(), scattered.end());
    SurfaceMesh::Render render;
    for (const auto& [code, p] : scattered) {
      render.positions.insert(render.positions.end(), p.begin(), p.end());
      render.normals.insert(render.normals.end(), {0.0f, 0.0f, 1.0f});
    }
    for (uint32_t i = 0; i + 2 < kRenderVertices; i += 3) render.triangles.insert(render.triangles.end(), {i, i + 1, i + 2});
    const std::vector<double> points(render.positions.begin(), render.positions.end());
    c.render = makeRenderMesh(render, mesh.mesh, embedPoints(mesh.mesh, points, 1e-3, "bench"), basis);
    const std::string bytes = formatModel(c);
    char message[256] = "";
    if (qv_model_load_memory(bytes.data(), bytes.size(), nullptr, nullptr, &model, message, sizeof message) != QV_OK) {
      std::fprintf(stderr, "%s\n", message);
      std::exit(1);
    }
    qv_instance_config config;
    qv_instance_config_init(&config, model);
    qv_instance_create(model, &config, nullptr, &instance);
    std::vector<double> q(kR), zero(kR, 0.0);
    for (double& value : q) value = u(random) - 0.5;
    qv_instance_set_state(instance, q.data(), zero.data(), zero.data());
    positions.resize(3 * size_t(kRenderVertices));
    normals.resize(positions.size());
    simulated.resize(3 * size_t(mesh.mesh.vertexCount()));
    scratch.resize(qv_model_render_scratch_size(model) / 8 + 1);
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "?";
}

void RenderPositions(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    qv_instance_render(f.instance, f.positions.data(), nullptr, f.scratch.data());
    benchmark::DoNotOptimize(f.positions.data());
  }
  state.counters["ns_per_vertex"] = benchmark::Counter(double(kRenderVertices), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void RenderPositionsAndNormals(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    qv_instance_render(f.instance, f.positions.data(), f.normals.data(), f.scratch.data());
    benchmark::DoNotOptimize(f.normals.data());
  }
  state.counters["ns_per_vertex"] = benchmark::Counter(double(kRenderVertices), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Today's output of the simulated vertices (U q per vertex): the per-vertex cost to match.
void SimulatedPositions(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    qv_instance_positions(f.instance, f.simulated.data());
    benchmark::DoNotOptimize(f.simulated.data());
  }
  state.counters["ns_per_vertex"] = benchmark::Counter(double(f.simulated.size() / 3), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

BENCHMARK(RenderPositions)->Unit(benchmark::kMicrosecond);
BENCHMARK(RenderPositionsAndNormals)->Unit(benchmark::kMicrosecond);
BENCHMARK(SimulatedPositions)->Unit(benchmark::kMicrosecond);

} // namespace

int main(int argc, char** argv) {
  std::printf("CPU: %s; 100000 render vertices on 12000 tets (2541 vertices), r = 30, one thread\n", cpuModel().c_str());
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
