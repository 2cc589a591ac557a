#include "apps/support/reduced_modes.h"

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

} // namespace quiver::app
