#include "common/rigid_body.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/SparseCore>

#include "common/mass_matrix.h"

namespace quiver {

RestMoments restMoments(const TetMesh& mesh, const std::vector<Material>& perTet) {
  if (static_cast<int>(perTet.size()) != mesh.tetCount())
    throw std::invalid_argument("rest moments: need one material per tet");
  RestMoments out;
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const double m = perTet[t].density * std::abs(signedVolume6(mesh, t)) / 6;
    for (int i : mesh.tets[t]) out.centre += 0.25 * m * mesh.vertices[i];
    out.mass += m;
  }
  out.centre /= out.mass;
  // Per tet, for y linear with corner values y_i: \int y y^T = V / 20 (sum y_i y_i^T + sum y_i (sum y_i)^T).
  for (int t = 0; t < mesh.tetCount(); ++t) {
    Eigen::Matrix3d squares = Eigen::Matrix3d::Zero();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i : mesh.tets[t]) {
      const Eigen::Vector3d y = mesh.vertices[i] - out.centre;
      squares += y * y.transpose(), sum += y;
    }
    out.secondMoment += perTet[t].density * std::abs(signedVolume6(mesh, t)) / 6 / 20 * (squares + sum * sum.transpose());
  }
  return out;
}

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

  const RestMoments rest = restMoments(mesh, perTet);
  RigidBodyMoments out;
  out.mass = rest.mass;
  out.centre = rest.centre;
  out.secondMoment = rest.secondMoment;
  Eigen::MatrixXd X(n, 3);
  for (int v = 0; v < n; ++v) X.row(v) = (mesh.vertices[v] - out.centre).transpose();
  const Eigen::MatrixXd MsX = Ms * X;
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
