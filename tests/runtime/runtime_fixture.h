#pragma once
// The suite's small model (tests/support/small_model.h, fixture test_model in tests/CMakeLists.txt),
// loaded through the C API, and the full-space reference rebuilt from what the .qvr itself stores:
// rest shape, tets, material and the float64 basis.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>

#include <Eigen/Core>

#include "common/stvk_force_model.h"
#include "formats/model/qvr.h"
#include "quiver/quiver.h"

namespace quiver::test {

struct TestModel {
  qv_model* model = nullptr;
  qv_model_info info{};
  TetMesh mesh;
  Eigen::MatrixXd U;  // 3n x r
  std::unique_ptr<StVKForceModel> full;

  TestModel() {
    const std::string path = QUIVER_RUNTIME_MODEL;
    char message[512] = "";
    EXPECT_EQ(qv_model_load_file(path.c_str(), nullptr, nullptr, &model, message, sizeof message), QV_OK) << message;
    if (!model) return;
    qv_model_get_info(model, &info);
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ModelView view;
    std::string error;
    EXPECT_TRUE(parseModel(bytes.data(), bytes.size(), view, error)) << error;
    EXPECT_NE(view.basis64, nullptr) << "the test model stores a float64 basis";
    EXPECT_NE(view.tets, nullptr);
    for (int v = 0; v < info.vertex_count; ++v)
      mesh.vertices.emplace_back(view.restPositions[3 * v], view.restPositions[3 * v + 1], view.restPositions[3 * v + 2]);
    for (int t = 0; t < info.tet_count; ++t)
      mesh.tets.push_back({int(view.tets[4 * t]), int(view.tets[4 * t + 1]), int(view.tets[4 * t + 2]), int(view.tets[4 * t + 3])});
    U = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(view.basis64, 3 * info.vertex_count, info.r);
    Material m;
    m.youngsModulus = info.youngs_modulus;
    m.poissonRatio = info.poisson_ratio;
    m.density = info.density;
    full = std::make_unique<StVKForceModel>(mesh, std::vector<Material>(mesh.tets.size(), m));
  }
  ~TestModel() { qv_model_destroy(model); }

  // The exact projection U^T R(Uq), U^T K(Uq) U.
  void exact(const Eigen::VectorXd& q, Eigen::VectorXd& force, Eigen::MatrixXd& stiffness) const {
    Eigen::VectorXd R;
    const Eigen::VectorXd u = U * q;
    full->internalForce(u, R);
    force = U.transpose() * R;
    stiffness = U.transpose() * full->tangentStiffness(u) * U;
  }
  double elasticEnergy(const Eigen::VectorXd& q) const { return full->energy(U * q); }

  // The vertex at the free end (x = max) nearest the section's centre line.
  int tipVertex() const {
    int best = 0;
    for (int v = 0; v < info.vertex_count; ++v)
      if (mesh.vertices[v].x() > mesh.vertices[best].x() + 1e-12 ||
          (std::abs(mesh.vertices[v].x() - mesh.vertices[best].x()) < 1e-12 &&
           mesh.vertices[v].tail<2>().norm() < mesh.vertices[best].tail<2>().norm()))
        best = v;
    return best;
  }
};

// Kinetic plus elastic energy (in flight, the frame's motion included).
inline double totalEnergy(const qv_instance* s) {
  double kinetic = 0, elastic = 0;
  qv_instance_energies(s, &kinetic, &elastic);
  return kinetic + elastic;
}

// An instance owned for the length of a test.
struct Instance {
  qv_instance* s = nullptr;
  Instance(const qv_model* model, const qv_instance_config& config) {
    EXPECT_EQ(qv_instance_create(model, &config, nullptr, &s), QV_OK);
  }
  ~Instance() { qv_instance_destroy(s); }
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;
};

} // namespace quiver::test
