#pragma once
// A free 0.6 x 0.1 x 0.1 bar (tests/support/small_model.h, free), loaded from memory, with the mesh's
// consistent mass to measure what the runtime hands out: centre of mass, momentum.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <gtest/gtest.h>

#include "common/box_mesh.h"
#include "common/mass_matrix.h"
#include "common/rigid_body.h"
#include "formats/model/qvr_writer.h"
#include "quiver/quiver.h"
#include "tests/support/small_model.h"

namespace quiver::test {

inline constexpr double kRho = 1000, kE = 1e6;

struct FreeBar {
  qv_model* model = nullptr;
  qv_model_info info{};
  Eigen::SparseMatrix<double> mass;  // n x n, the consistent mass's x-x block

  // derivativeAmplitude: SmallModelSpec's (1, the suite's bases), or bakesAmplitude().
  explicit FreeBar(int rank = 10, std::array<int, 3> cells = {6, 1, 1}, Eigen::Vector3d size = {0.6, 0.1, 0.1},
                   double derivativeAmplitude = 1) {
    test::SmallModelSpec spec;
    spec.size = size;
    spec.cells = cells;
    spec.free = true;
    spec.rank = rank;
    spec.youngsModulus = kE;
    spec.density = kRho;
    spec.derivativeAmplitude = derivativeAmplitude;
    const ModelContents contents = test::smallBeamModel(spec);
    const std::string bytes = formatModel(contents);
    char message[512] = "";
    EXPECT_EQ(qv_model_load_memory(bytes.data(), bytes.size(), nullptr, nullptr, &model, message, sizeof message), QV_OK)
        << message;
    qv_model_get_info(model, &info);
    TetMesh mesh;
    for (size_t v = 0; v < contents.restPositions.size() / 3; ++v)
      mesh.vertices.emplace_back(contents.restPositions[3 * v], contents.restPositions[3 * v + 1], contents.restPositions[3 * v + 2]);
    for (size_t t = 0; t < contents.tets.size() / 4; ++t)
      mesh.tets.push_back({int(contents.tets[4 * t]), int(contents.tets[4 * t + 1]), int(contents.tets[4 * t + 2]),
                           int(contents.tets[4 * t + 3])});
    Material m;
    m.density = kRho;
    const Eigen::SparseMatrix<double> full = consistentMassMatrix(mesh, std::vector<Material>(mesh.tets.size(), m));
    std::vector<Eigen::Triplet<double>> entries;
    for (int col = 0; col < full.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(full, col); it; ++it)
        if (it.row() % 3 == 0 && it.col() % 3 == 0) entries.emplace_back(it.row() / 3, it.col() / 3, it.value());
    mass.resize(mesh.vertexCount(), mesh.vertexCount());
    mass.setFromTriplets(entries.begin(), entries.end());
  }
  ~FreeBar() { qv_model_destroy(model); }

  // The derivatives' weight quiver-bake gives a bar of this size by default (--pca-amplitude 0.3
  // times its extent ||X - c||_M, precompute/stages/basis.h; 0.13 for the default bar), for a basis
  // weighted as the bake's (of this bar's k = 6 and r = 10, not the bake's 20 and 30).
  static double bakesAmplitude(Eigen::Vector3d size = {0.6, 0.1, 0.1}) {
    Material m;
    m.density = kRho;
    const TetMesh box = makeBoxMesh(size, {6, 1, 1});
    return 0.3 * std::sqrt(restMoments(box, std::vector<Material>(box.tetCount(), m)).secondMoment.trace());
  }

  qv_instance_config config(double h) const {
    qv_instance_config c;
    qv_instance_config_init(&c, model);
    c.free_flight = 1;
    c.time_step = h;
    c.rayleigh_alpha = c.rayleigh_beta = 0;
    return c;
  }
  Eigen::MatrixXd positions(const qv_instance* s) const {
    std::vector<float> p(3 * static_cast<size_t>(info.vertex_count));
    qv_instance_positions(s, p.data());
    Eigen::MatrixXd out(info.vertex_count, 3);
    for (int v = 0; v < info.vertex_count; ++v)
      for (int c = 0; c < 3; ++c) out(v, c) = p[3 * v + c];
    return out;
  }
  Eigen::Vector3d centre(const Eigen::MatrixXd& x) const {  // exact for the linear field x
    const Eigen::VectorXd w = mass * Eigen::VectorXd::Ones(info.vertex_count);
    return x.transpose() * w / w.sum();
  }
  // Linear and angular momentum (about the origin) of positions x moving with velocities xd:
  // \int rho x' and \int rho x x x', as the consistent mass integrates them.
  void momentum(const Eigen::MatrixXd& x, const Eigen::MatrixXd& xd, Eigen::Vector3d& P, Eigen::Vector3d& L) const {
    const Eigen::MatrixXd Mxd = mass * xd;
    P = Mxd.colwise().sum().transpose();
    L.setZero();
    for (int v = 0; v < info.vertex_count; ++v) L += Eigen::Vector3d(x.row(v)).cross(Eigen::Vector3d(Mxd.row(v)));
  }
};

} // namespace quiver::test
