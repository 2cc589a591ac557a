#include "common/tet_elements.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/LU>

namespace quiver {

TetElements computeTetElements(const TetMesh& mesh) {
  TetElements out;
  out.volume.resize(mesh.tets.size());
  out.gradients.resize(mesh.tets.size());
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const Tet& v = mesh.tets[t];
    const Eigen::Vector3d& x0 = mesh.vertices[v[0]];
    Eigen::Matrix3d dm;
    dm << mesh.vertices[v[1]] - x0, mesh.vertices[v[2]] - x0, mesh.vertices[v[3]] - x0;
    const double det = dm.determinant();
    const Eigen::Matrix3d dmInv = dm.inverse();
    if (!std::isfinite(det) || det == 0 || !dmInv.allFinite())
      throw std::invalid_argument("computeTetElements: tet " + std::to_string(t) + " is degenerate (zero volume)");
    out.volume[t] = std::abs(det) / 6.0;
    // N_a(X) = row (a-1) of D_m^{-1} applied to (X - X_0) for a = 1..3, hence those rows are g_a.
    Matrix34& g = out.gradients[t];
    g.rightCols<3>() = dmInv.transpose();
    g.col(0) = -g.rightCols<3>().rowwise().sum();
  }
  return out;
}

Matrix34 tetDisplacements(const Tet& tet, const Eigen::VectorXd& u) {
  Matrix34 ue;
  for (int a = 0; a < 4; ++a) ue.col(a) = u.segment<3>(3 * tet[a]);
  return ue;
}

Eigen::Matrix3d displacementGradient(const Matrix34& ue, const Matrix34& gradients) {
  return ue * gradients.transpose();
}

} // namespace quiver
