#include "apps/support/reduced_modes.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

namespace quiver::app {

ReducedModes reducedModes(const qv_model* model) {
  qv_model_info info;
  qv_model_get_info(model, &info);
  const int r = info.r;
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(r);
  Eigen::MatrixXd stiffness(r, r);  // symmetric, so row- or column-major reads alike
  std::vector<double> scratch(qv_model_scratch_size(model) / sizeof(double) + 1);
  qv_model_evaluate(model, q.data(), nullptr, nullptr, stiffness.data(), scratch.data());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(stiffness);
  return {solver.eigenvalues(), solver.eigenvectors()};
}

Eigen::VectorXd withLargestDisplacement(const qv_model* model, const Eigen::VectorXd& q, double amplitude) {
  qv_model_info info;
  qv_model_get_info(model, &info);
  std::vector<float> u(3 * static_cast<size_t>(info.vertex_count));
  qv_model_displacements(model, q.data(), u.data());
  double largest = 0;
  for (size_t v = 0; v < u.size(); v += 3) largest = std::max(largest, std::hypot(double(u[v]), double(u[v + 1]), double(u[v + 2])));
  return largest > 0 ? Eigen::VectorXd(q * (amplitude / largest)) : Eigen::VectorXd(Eigen::VectorXd::Zero(q.size()));
}

} // namespace quiver::app
