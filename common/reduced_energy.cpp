#include "common/reduced_energy.h"

#include <cmath>

#include <Eigen/Cholesky>

namespace quiver {

namespace {

// Symmetric 3x3 as the 6-vector (xx, yy, zz, yz, xz, xy), scaled by `s`.
inline void voigt(const Eigen::Matrix3d& A, double s, double* out) {
  out[0] = s * A(0, 0);
  out[1] = s * A(1, 1);
  out[2] = s * A(2, 2);
  out[3] = s * 0.5 * (A(1, 2) + A(2, 1));
  out[4] = s * 0.5 * (A(0, 2) + A(2, 0));
  out[5] = s * 0.5 * (A(0, 1) + A(1, 0));
}

// C with C^T C = V (\mu W + \tfrac{\lambda}{2} t t^T): the normal block is dense, the shear block diagonal.
Eigen::Matrix<double, 6, 6> energyFactor(double V, double lambda, double mu) {
  Eigen::Matrix3d normal = V * (mu * Eigen::Matrix3d::Identity() + 0.5 * lambda * Eigen::Matrix3d::Ones());
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  C.topLeftCorner<3, 3>() = normal.llt().matrixU();
  C.bottomRightCorner<3, 3>().diagonal().setConstant(std::sqrt(2 * mu * V));
  return C;
}

} // namespace

ReducedEnergyRows::ReducedEnergyRows(int r) : r_(r), G_(r), LS_(6, r + r * (r + 1) / 2) {}

void ReducedEnergyRows::write(const Eigen::MatrixXd& U, const Tet& tet, const Matrix34& grad, double volume,
                              const Material& material, double* B, int64_t ld) {
  for (int j = 0; j < r_; ++j) {
    Matrix34 Ue;
    for (int a = 0; a < 4; ++a) Ue.col(a) = U.block<3, 1>(3 * tet[a], j);
    G_[j] = Ue * grad.transpose();
  }
  for (int j = 0; j < r_; ++j) voigt(G_[j], 1.0, LS_.col(j).data());
  int column = r_;
  for (int j = 0; j < r_; ++j)
    for (int k = j; k < r_; ++k) voigt(G_[j].transpose() * G_[k], j == k ? 0.5 : 1.0, LS_.col(column++).data());
  Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic>, 0, Eigen::OuterStride<>> rows(B, 6, LS_.cols(),
                                                                                    Eigen::OuterStride<>(ld));
  rows.noalias() = energyFactor(volume, material.lambda(), material.mu()).triangularView<Eigen::Upper>() * LS_;
}

Eigen::MatrixXd reducedEnergyGram(const TetMesh& mesh, const std::vector<Material>& perTet,
                                  const Eigen::MatrixXd& basis) {
  const TetElements elements = computeTetElements(mesh);
  ReducedEnergyRows rows(static_cast<int>(basis.cols()));
  Eigen::MatrixXd B(6, rows.columns()), gram = Eigen::MatrixXd::Zero(rows.columns(), rows.columns());
  for (int t = 0; t < mesh.tetCount(); ++t) {
    rows.write(basis, mesh.tets[t], elements.gradients[t], elements.volume[t], perTet[t], B.data(), 6);
    gram.selfadjointView<Eigen::Upper>().rankUpdate(B.transpose());
  }
  return gram;
}

} // namespace quiver
