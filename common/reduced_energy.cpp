#include "common/reduced_energy.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace quiver {

namespace {

// C with C^T C = V (\mu W + \tfrac{\lambda}{2} t t^T): the normal block is dense, the shear block diagonal.
Eigen::Matrix<double, 6, 6> energyFactor(double V, double lambda, double mu) {
  Eigen::Matrix3d normal = V * (mu * Eigen::Matrix3d::Identity() + 0.5 * lambda * Eigen::Matrix3d::Ones());
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  C.topLeftCorner<3, 3>() = normal.llt().matrixU();
  C.bottomRightCorner<3, 3>().diagonal().setConstant(std::sqrt(2 * mu * V));
  return C;
}

} // namespace

ReducedEnergyRows::ReducedEnergyRows(const Eigen::MatrixXd& basis, const TetMesh& mesh, const std::vector<int>& tets)
    : r_(static_cast<int>(basis.cols())), row_(mesh.vertexCount(), -1), g_(9 * static_cast<size_t>(r_)),
      strain_(6 * static_cast<size_t>(r_)) {
  int used = 0;
  for (int t : tets)
    for (int v : mesh.tets[t])
      if (row_[v] < 0) row_[v] = used++;
  vertexMajor_.resize(3 * static_cast<Eigen::Index>(used), r_);
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if (row_[v] >= 0) vertexMajor_.middleRows<3>(3 * static_cast<Eigen::Index>(row_[v])) = basis.middleRows<3>(3 * static_cast<Eigen::Index>(v));
}

void ReducedEnergyRows::write(const Tet& tet, const Matrix34& grad, double volume, const Material& material, double* B,
                              int64_t ld) {
  const int r = r_;
  // G_j(c, d) = sum_v U(3 tet[v] + c, j) grad(d, v): 36 axpys of length r.
  std::fill(g_.begin(), g_.end(), 0.0);
  for (int v = 0; v < 4; ++v)
    for (int c = 0; c < 3; ++c) {
      const double* row = vertexMajor_.data() + (3 * static_cast<int64_t>(row_[tet[v]]) + c) * r;
      for (int d = 0; d < 3; ++d) {
        double* out = g_.data() + (3 * c + d) * r;
        const double w = grad(d, v);
        for (int j = 0; j < r; ++j) out[j] += w * row[j];
      }
    }
  const auto g = [&](int c, int d) { return g_.data() + (3 * c + d) * r; };
  // C with C^T C = V (mu W + lambda/2 t t^T): rows of B are C times the Voigt columns.
  const Eigen::Matrix<double, 6, 6> C = energyFactor(volume, material.lambda(), material.mu());
  const double c00 = C(0, 0), c01 = C(0, 1), c02 = C(0, 2), c11 = C(1, 1), c12 = C(1, 2), c22 = C(2, 2), cs = C(3, 3);
  const auto put = [&](int64_t column, double xx, double yy, double zz, double yz, double xz, double xy) {
    double* b = B + column * ld;
    b[0] = c00 * xx + c01 * yy + c02 * zz;
    b[1] = c11 * yy + c12 * zz;
    b[2] = c22 * zz;
    b[3] = cs * yz;
    b[4] = cs * xz;
    b[5] = cs * xy;
  };
  // Linear part: column j is sym(G_j).
  for (int j = 0; j < r; ++j)
    put(j, g(0, 0)[j], g(1, 1)[j], g(2, 2)[j], 0.5 * (g(1, 2)[j] + g(2, 1)[j]), 0.5 * (g(0, 2)[j] + g(2, 0)[j]),
        0.5 * (g(0, 1)[j] + g(1, 0)[j]));
  // Quadratic part: column (j, k), k >= j, is sym(G_j^T G_k) (halved on the diagonal): for each j,
  // the six components as vector loops over k.
  int64_t column = r;
  double* e = strain_.data();
  for (int j = 0; j < r; ++j) {
    for (int k = j; k < r; ++k) {
      double xx = 0, yy = 0, zz = 0, yz = 0, xz = 0, xy = 0;
      for (int c = 0; c < 3; ++c) {
        const double* x = g(c, 0);
        const double* y = g(c, 1);
        const double* z = g(c, 2);
        xx += x[j] * x[k];
        yy += y[j] * y[k];
        zz += z[j] * z[k];
        yz += y[j] * z[k] + z[j] * y[k];
        xz += x[j] * z[k] + z[j] * x[k];
        xy += x[j] * y[k] + y[j] * x[k];
      }
      e[k] = xx, e[r + k] = yy, e[2 * r + k] = zz, e[3 * r + k] = 0.5 * yz, e[4 * r + k] = 0.5 * xz, e[5 * r + k] = 0.5 * xy;
    }
    for (int m = 0; m < 6; ++m) e[m * r + j] *= 0.5;  // z_jj = q_j^2 enters once: G_j^T G_j / 2
    for (int k = j; k < r; ++k) put(column++, e[k], e[r + k], e[2 * r + k], e[3 * r + k], e[4 * r + k], e[5 * r + k]);
  }
}

Eigen::MatrixXd reducedEnergyGram(const TetMesh& mesh, const std::vector<Material>& perTet,
                                  const Eigen::MatrixXd& basis) {
  const TetElements elements = computeTetElements(mesh);
  std::vector<int> all(mesh.tetCount());
  for (int t = 0; t < mesh.tetCount(); ++t) all[t] = t;
  ReducedEnergyRows rows(basis, mesh, all);
  Eigen::MatrixXd B(6, rows.columns()), gram = Eigen::MatrixXd::Zero(rows.columns(), rows.columns());
  for (int t = 0; t < mesh.tetCount(); ++t) {
    rows.write(mesh.tets[t], elements.gradients[t], elements.volume[t], perTet[t], B.data(), 6);
    gram.selfadjointView<Eigen::Upper>().rankUpdate(B.transpose());
  }
  return gram;
}

} // namespace quiver
