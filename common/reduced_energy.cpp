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
  // C with C^T C = V (mu W + lambda/2 t t^T): row i of B is row i of C times the Voigt components.
  const Eigen::Matrix<double, 6, 6> C = energyFactor(volume, material.lambda(), material.mu());
  const double c00 = C(0, 0), c01 = C(0, 1), c02 = C(0, 2), c11 = C(1, 1), c12 = C(1, 2), c22 = C(2, 2), cs = C(3, 3);
  double* b[6];
  for (int i = 0; i < 6; ++i) b[i] = B + i * ld;
  // Columns [first, first + n) of B from the six Voigt components over them.
  const auto put = [&](int64_t first, int n, const double* xx, const double* yy, const double* zz, const double* yz,
                       const double* xz, const double* xy) {
    for (int k = 0; k < n; ++k) {
      b[0][first + k] = c00 * xx[k] + c01 * yy[k] + c02 * zz[k];
      b[1][first + k] = c11 * yy[k] + c12 * zz[k];
      b[2][first + k] = c22 * zz[k];
      b[3][first + k] = cs * yz[k];
      b[4][first + k] = cs * xz[k];
      b[5][first + k] = cs * xy[k];
    }
  };
  // Linear part: column j is sym(G_j).
  double* e = strain_.data();
  for (int j = 0; j < r; ++j) {
    e[3 * r + j] = 0.5 * (g(1, 2)[j] + g(2, 1)[j]);
    e[4 * r + j] = 0.5 * (g(0, 2)[j] + g(2, 0)[j]);
    e[5 * r + j] = 0.5 * (g(0, 1)[j] + g(1, 0)[j]);
  }
  put(0, r, g(0, 0), g(1, 1), g(2, 2), e + 3 * r, e + 4 * r, e + 5 * r);
  // Quadratic part: column (j, k), k >= j, is sym(G_j^T G_k) (halved on the diagonal): for each j,
  // the six components as vector loops over k.
  int64_t column = r;
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
    put(column, r - j, e + j, e + r + j, e + 2 * r + j, e + 3 * r + j, e + 4 * r + j, e + 5 * r + j);
    column += r - j;
  }
}

Eigen::MatrixXd reducedEnergyGram(const TetMesh& mesh, const std::vector<Material>& perTet,
                                  const Eigen::MatrixXd& basis) {
  const TetElements elements = computeTetElements(mesh);
  std::vector<int> all(mesh.tetCount());
  for (int t = 0; t < mesh.tetCount(); ++t) all[t] = t;
  ReducedEnergyRows rows(basis, mesh, all);
  Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor> B(6, rows.columns());
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(rows.columns(), rows.columns());
  for (int t = 0; t < mesh.tetCount(); ++t) {
    rows.write(mesh.tets[t], elements.gradients[t], elements.volume[t], perTet[t], B.data(), rows.columns());
    gram.selfadjointView<Eigen::Upper>().rankUpdate(B.transpose());
  }
  return gram;
}

} // namespace quiver
