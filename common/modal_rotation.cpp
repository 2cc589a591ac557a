#include "common/modal_rotation.h"


#include "common/tet_elements.h"

namespace quiver {

Eigen::MatrixXd vertexRotations(const TetMesh& mesh, const Eigen::MatrixXd& fields) {
  const TetElements elements = computeTetElements(mesh);
  const Eigen::Index r = fields.cols();
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(fields.rows(), r);
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(mesh.vertexCount());
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const Tet& tet = mesh.tets[t];
    const double V = elements.volume[t];
    for (Eigen::Index j = 0; j < r; ++j) {
      Matrix34 ue;
      for (int a = 0; a < 4; ++a) ue.col(a) = fields.block<3, 1>(3 * tet[a], j);
      const Eigen::Matrix3d H = ue * elements.gradients[t].transpose();  // H_ik = d u_i / d x_k
      const Eigen::Vector3d w(0.5 * (H(2, 1) - H(1, 2)), 0.5 * (H(0, 2) - H(2, 0)), 0.5 * (H(1, 0) - H(0, 1)));
      for (int a = 0; a < 4; ++a) sum.block<3, 1>(3 * tet[a], j) += V * w;
    }
    for (int a = 0; a < 4; ++a) weight[tet[a]] += V;
  }
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if (weight[v] > 0) sum.middleRows(3 * v, 3) /= weight[v];
  return sum;
}

} // namespace quiver
