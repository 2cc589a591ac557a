// A render mesh embedded in the tets (runtime/src/render_mesh.h): its deformed positions are the
// weights' interpolation of the deformed tet vertices (as qv_instance_positions gives them), also
// for a vertex outside its tet (extrapolated); the baked render basis gives the same positions;
// its normals are those of its deformed triangles wherever a triangle lies in one tet (the map is
// affine there, so the deformed face normal is exact); in flight all of it in the world.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "formats/model/qvr_writer.h"
#include "quiver/quiver.h"
#include "runtime_fixture.h"
#include "tests/support/small_model.h"

namespace quiver {
namespace {

// Each tet of the beam carries a small triangle (weights inside it; every third tet's third corner
// outside, extrapolated) with its face normal and UVs; the render basis is W U.
ModelContents withRenderMesh(ModelContents c) {
  ModelContents::RenderMesh& m = c.render;
  const size_t r = c.info.r, tets = c.tets.size() / 4;
  const float corners[3][4] = {{0.6f, 0.2f, 0.1f, 0.1f}, {0.1f, 0.6f, 0.2f, 0.1f}, {0.1f, 0.1f, 0.6f, 0.2f}};
  const float outside[4] = {-0.1f, 0.2f, 0.7f, 0.2f};
  for (size_t t = 0; t < tets; ++t) {
    for (int k = 0; k < 3; ++k) {
      const float* w = k == 2 && t % 3 == 0 ? outside : corners[k];
      const uint32_t* v = &c.tets[4 * t];
      m.tets.push_back(static_cast<uint32_t>(t));
      m.weights.insert(m.weights.end(), w, w + 4);
      for (int a = 0; a < 3; ++a) {
        double x = 0;
        for (int j = 0; j < 4; ++j) x += w[j] * c.restPositions[3 * v[j] + a];
        m.positions.push_back(static_cast<float>(x));
      }
      for (size_t row = 0; row < 3; ++row)
        for (size_t col = 0; col < r; ++col) {
          double b = 0;
          for (int j = 0; j < 4; ++j) b += w[j] * c.basis[(3 * v[j] + row) * r + col];
          m.basis.push_back(static_cast<float>(b));
        }
      m.uvs.insert(m.uvs.end(), {float(k), float(t)});
    }
    const uint32_t first = static_cast<uint32_t>(3 * t);
    m.triangles.insert(m.triangles.end(), {first, first + 1, first + 2});
    const Eigen::Vector3f a(&m.positions[3 * first]), b(&m.positions[3 * first + 3]), d(&m.positions[3 * first + 6]);
    const Eigen::Vector3f n = (b - a).cross(d - a).normalized();
    for (int k = 0; k < 3; ++k) m.normals.insert(m.normals.end(), {n.x(), n.y(), n.z()});
  }
  return c;
}

struct Loaded {
  ModelContents contents;
  qv_model* model = nullptr;
  explicit Loaded(bool free) {
    test::SmallModelSpec spec;
    spec.free = free;
    spec.cells = {4, 1, 1};
    contents = withRenderMesh(test::smallBeamModel(spec));
    const std::string bytes = formatModel(contents);
    char message[256] = "";
    EXPECT_EQ(qv_model_load_memory(bytes.data(), bytes.size(), nullptr, nullptr, &model, message, sizeof message), QV_OK) << message;
  }
  ~Loaded() { qv_model_destroy(model); }
};

// Render positions and normals of `s` against the interpolation of its tet vertices and the
// normals of its deformed triangles; the largest differences (m, and of unit normals).
void compare(const Loaded& l, const qv_instance* s, double& position, double& normal) {
  qv_model_info info;
  qv_model_get_info(l.model, &info);
  const size_t V = static_cast<size_t>(info.render_vertex_count);
  std::vector<float> x(3 * static_cast<size_t>(info.vertex_count)), p(3 * V), n(3 * V);
  std::vector<double> scratch(qv_model_render_scratch_size(l.model) / 8 + 1);
  qv_instance_positions(s, x.data());
  ASSERT_EQ(qv_instance_render(s, p.data(), n.data(), scratch.data()), QV_OK);
  position = normal = 0;
  const ModelContents::RenderMesh& m = l.contents.render;
  for (size_t i = 0; i < V; ++i)
    for (int a = 0; a < 3; ++a) {
      double expected = 0;
      for (int j = 0; j < 4; ++j) expected += m.weights[4 * i + j] * x[3 * l.contents.tets[4 * m.tets[i] + j] + a];
      position = std::max(position, std::fabs(expected - p[3 * i + a]));
    }
  for (size_t t = 0; t < m.triangles.size() / 3; ++t) {
    const Eigen::Vector3f a(&p[9 * t]), b(&p[9 * t + 3]), c(&p[9 * t + 6]);
    const Eigen::Vector3f face = (b - a).cross(c - a).normalized();
    for (int k = 0; k < 3; ++k) normal = std::max(normal, double((Eigen::Vector3f(&n[9 * t + 3 * k]) - face).norm()));
  }
}

TEST(RenderMesh, FollowsTheTetsItIsEmbeddedIn) {
  Loaded l(false);
  qv_model_info info;
  qv_model_get_info(l.model, &info);
  ASSERT_EQ(info.render_vertex_count, 3 * info.tet_count);
  EXPECT_EQ(info.render_triangle_count, info.tet_count);
  const size_t V = static_cast<size_t>(info.render_vertex_count);
  // At rest: the positions, normals and UVs as given.
  for (size_t i = 0; i < 3 * V; ++i) ASSERT_EQ(qv_model_render_rest_positions(l.model)[i], l.contents.render.positions[i]);
  for (size_t i = 0; i < 2 * V; ++i) ASSERT_EQ(qv_model_render_uvs(l.model)[i], l.contents.render.uvs[i]);
  qv_instance_config config;
  qv_instance_config_init(&config, l.model);
  test::Instance inst(l.model, config);
  // A large deformation: q of a tenth of the beam's size in every mode.
  std::mt19937 random(5);
  std::uniform_real_distribution<double> pick(-1, 1);
  std::vector<double> q(static_cast<size_t>(info.r)), zero(q.size(), 0.0);
  for (double& value : q) value = 0.02 * pick(random);
  qv_instance_set_state(inst.s, q.data(), zero.data(), zero.data());
  double position, normal;
  compare(l, inst.s, position, normal);
  std::printf("deformed: render positions within %.2g m of the interpolated tets, normals within %.2g of the deformed faces'\n",
              position, normal);
  EXPECT_LT(position, 1e-6);
  EXPECT_LT(normal, 1e-4);
  // The render basis (for shaders) gives the same positions.
  std::vector<float> p(3 * V), n(3 * V);
  std::vector<double> scratch(qv_model_render_scratch_size(l.model) / 8 + 1);
  ASSERT_EQ(qv_instance_render(inst.s, p.data(), nullptr, scratch.data()), QV_OK);
  double basis = 0;
  for (size_t row = 0; row < 3 * V; ++row) {
    double u = l.contents.render.positions[row];
    for (size_t j = 0; j < q.size(); ++j) u += double(l.contents.render.basis[row * q.size() + j]) * q[j];
    basis = std::max(basis, std::fabs(u - p[row]));
  }
  EXPECT_LT(basis, 1e-6);
  // Bad use.
  EXPECT_EQ(qv_instance_render(inst.s, nullptr, n.data(), scratch.data()), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_instance_render(inst.s, p.data(), n.data(), nullptr), QV_ERROR_INVALID_ARGUMENT);
}

TEST(RenderMesh, InFlightItIsInTheWorld) {
  Loaded l(true);
  qv_model_info info;
  qv_model_get_info(l.model, &info);
  qv_instance_config config;
  qv_instance_config_init(&config, l.model);
  config.free_flight = 1;
  test::Instance inst(l.model, config);
  const qv_rigid_state turned{{1, 2, 3}, {0.8, 0.2, 0.4, 0.4}, {0, 0, 0}, {0, 0, 0}};
  ASSERT_EQ(qv_instance_set_rigid_state(inst.s, &turned), QV_OK);
  std::vector<double> q(static_cast<size_t>(info.r), 0.01), zero(q.size(), 0.0);
  qv_instance_set_state(inst.s, q.data(), zero.data(), zero.data());
  double position, normal;
  compare(l, inst.s, position, normal);
  std::printf("in flight: within %.2g m and %.2g\n", position, normal);
  EXPECT_LT(position, 1e-5);  // float32 world positions 3 m from the origin
  EXPECT_LT(normal, 1e-4);
}

TEST(RenderMesh, AModelWithoutOneSaysSo) {
  test::SmallModelSpec spec;
  spec.cells = {4, 1, 1};
  const std::string bytes = formatModel(test::smallBeamModel(spec));
  qv_model* model = nullptr;
  ASSERT_EQ(qv_model_load_memory(bytes.data(), bytes.size(), nullptr, nullptr, &model, nullptr, 0), QV_OK);
  qv_model_info info;
  qv_model_get_info(model, &info);
  EXPECT_EQ(info.render_vertex_count, 0);
  EXPECT_EQ(qv_model_render_rest_positions(model), nullptr);
  EXPECT_EQ(qv_model_render_scratch_size(model), 0u);
  qv_instance_config config;
  qv_instance_config_init(&config, model);
  {
    test::Instance inst(model, config);
    float p[3];
    double scratch[4];
    EXPECT_EQ(qv_instance_render(inst.s, p, nullptr, scratch), QV_ERROR_INVALID_ARGUMENT);
  }
  qv_model_destroy(model);
}

} // namespace
} // namespace quiver
