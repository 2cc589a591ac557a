// Output buffers and sharing: positions, surface normals, and one model stepped by instances on
// several threads at once giving the same bits as one after the other.
#include <gtest/gtest.h>

#include <thread>

#include "tests/runtime/runtime_fixture.h"

TEST(Output, RestNormalsOfABoxPointOutOfItsFaces) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int n = m.info.vertex_count;
  std::vector<float> rest(3 * n), normals(3 * n);
  for (int i = 0; i < 3 * n; ++i) rest[i] = static_cast<float>(qv_model_rest_positions(m.model)[i]);
  qv_model_surface_normals(m.model, rest.data(), normals.data());
  int checked = 0;
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d x = m.mesh.vertices[v];
    const Eigen::Vector3f normal(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
    // Vertices inside one face of the 0.6 x 0.1 x 0.1 box (not on an edge): the face's outward normal.
    const bool yFace = (x.y() == 0 || x.y() == 0.1) && x.z() > 1e-9 && x.z() < 0.1 - 1e-9 && x.x() > 1e-9 && x.x() < 0.6 - 1e-9;
    if (yFace) {
      EXPECT_NEAR(normal.y(), x.y() == 0 ? -1 : 1, 1e-6) << "vertex " << v;
      ++checked;
    }
    if (x.y() > 1e-9 && x.y() < 0.1 - 1e-9 && x.z() > 1e-9 && x.z() < 0.1 - 1e-9 && x.x() > 1e-9 && x.x() < 0.6 - 1e-9) {
      EXPECT_EQ(normal.norm(), 0.0f) << "interior vertex " << v;
    }
  }
  EXPECT_GT(checked, 0);
}

TEST(Output, InstancesOnThreadsMatchSequentialStepping) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r, threads = 4;
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  auto run = [&](int index, std::vector<double>& q) {
    qv_instance* s = nullptr;
    qv_instance_create(m.model, &config, nullptr, &s);
    const double g[3] = {0, 0.1 * index, -9.81};
    qv_instance_set_gravity(s, g);
    for (int step = 0; step < 300; ++step) qv_instance_step(s);
    q.resize(r);
    qv_instance_get_state(s, q.data(), nullptr, nullptr);
    qv_instance_destroy(s);
  };
  std::vector<std::vector<double>> sequential(threads), parallel(threads);
  for (int i = 0; i < threads; ++i) run(i, sequential[i]);
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(run, i, std::ref(parallel[i]));
  for (auto& t : pool) t.join();
  for (int i = 0; i < threads; ++i) EXPECT_EQ(sequential[i], parallel[i]) << "instance " << i;
  EXPECT_NE(sequential[0], sequential[1]);  // different loads, different states: the comparison means something
}
