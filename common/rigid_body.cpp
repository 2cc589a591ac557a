#include "common/rigid_body.h"

#include <stdexcept>

#include <Eigen/SparseCore>

#include "common/mass_matrix.h"

namespace quiver {

RigidBodyMoments rigidBodyMoments(const TetMesh& mesh, const std::vector<Material>& perTet,
                                  const Eigen::MatrixXd& basis) {
  const int n = mesh.vertexCount();
  if (basis.rows() != 3 * n) throw std::invalid_argument("rigidBodyMoments: the basis needs 3 rows per vertex");
  // The consistent mass does not couple components: its x-x block is the scalar mass matrix.
  const Eigen::SparseMatrix<double> full = consistentMassMatrix(mesh, perTet);
  std::vector<Eigen::Triplet<double>> entries;
  for (int col = 0; col < full.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(full, col); it; ++it)
      if (it.row() % 3 == 0 && it.col() % 3 == 0) entries.emplace_back(it.row() / 3, it.col() / 3, it.value());
  Eigen::SparseMatrix<double> Ms(n, n);
  Ms.setFromTriplets(entries.begin(), entries.end());

  RigidBodyMoments out;
  Eigen::MatrixXd X(n, 3);
  for (int v = 0; v < n; ++v) X.row(v) = mesh.vertices[v].transpose();
  const Eigen::VectorXd weights = Ms * Eigen::VectorXd::Ones(n);  // row sums: the lumped masses
  out.mass = weights.sum();
  out.centre = X.transpose() * weights / out.mass;
  X.rowwise() -= out.centre.transpose();
  const Eigen::MatrixXd MsX = Ms * X;
  const Eigen::Matrix3d S = X.transpose() * MsX;
  out.secondMoment = 0.5 * (S + S.transpose());  // symmetric to the bit, as the .qvr requires
  const Eigen::Index r = basis.cols();
  std::vector<Eigen::MatrixXd> component(3), massComponent(3);  // U_a (n x r) and Ms U_a
  for (int a = 0; a < 3; ++a) {
    component[a].resize(n, r);
    for (int v = 0; v < n; ++v) component[a].row(v) = basis.row(3 * v + a);
    massComponent[a] = Ms * component[a];
  }
  out.first.resize(9, r);
  out.second.resize(9);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      out.first.row(3 * a + b) = MsX.col(a).transpose() * component[b];
      out.second[3 * a + b] = component[a].transpose() * massComponent[b];
    }
  return out;
}

} // namespace quiver
