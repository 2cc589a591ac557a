#include "precompute/rigid_modes.h"

#include <Eigen/Cholesky>

#include "precompute/distributed_dense.h"

namespace quiver {

Eigen::MatrixXd rigidModes(const TetMesh& mesh, Mat mass, const DofLayout& layout) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& x : mesh.vertices) centroid += x;
  centroid /= mesh.vertexCount();
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(layout.localDofs(), 6);
  for (size_t i = 0; i < layout.ownedVertices().size(); ++i) {
    const Eigen::Vector3d x = mesh.vertices[layout.ownedVertices()[i]] - centroid;
    R.block<3, 3>(3 * i, 0).setIdentity();
    R.block<3, 3>(3 * i, 3) << 0, x.z(), -x.y(), -x.z(), 0, x.x(), x.y(), -x.x(), 0;  // columns: e_k x x
  }
  const Eigen::MatrixXd gram = innerProducts(R, multiply(mass, R, layout), layout.comm());
  const Eigen::MatrixXd L = gram.llt().matrixL();
  return L.triangularView<Eigen::Lower>().solve(R.transpose()).transpose();  // R L^{-T}
}

} // namespace quiver
