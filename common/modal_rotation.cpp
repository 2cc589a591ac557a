#include "common/modal_rotation.h"

#include "common/tet_elements.h"

namespace quiver {

Eigen::MatrixXd vertexRotations(const TetMesh& mesh, const Eigen::MatrixXd& fields) {
  // Row-major, so that a vertex's three rows of all r fields are one contiguous block.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const TetElements elements = computeTetElements(mesh);
  const RowMajor u = fields;
  RowMajor sum = RowMajor::Zero(fields.rows(), fields.cols());
  RowMajor w(3, fields.cols());
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(mesh.vertexCount());
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const Tet& tet = mesh.tets[t];
    const Matrix34& G = elements.gradients[t];
    // w = (1/2) curl u = (1/2) sum_a g_a x u_a, every field at once.
    w.setZero();
    for (int a = 0; a < 4; ++a) {
      const auto ua = u.middleRows<3>(3 * tet[a]);
      w.row(0) += G(1, a) * ua.row(2) - G(2, a) * ua.row(1);
      w.row(1) += G(2, a) * ua.row(0) - G(0, a) * ua.row(2);
      w.row(2) += G(0, a) * ua.row(1) - G(1, a) * ua.row(0);
    }
    const double V = elements.volume[t];
    for (int a = 0; a < 4; ++a) {
      sum.middleRows<3>(3 * tet[a]) += (0.5 * V) * w;
      weight[tet[a]] += V;
    }
  }
  for (int v = 0; v < mesh.vertexCount(); ++v)
    if (weight[v] > 0) sum.middleRows<3>(3 * v) /= weight[v];
  return sum;
}

} // namespace quiver
