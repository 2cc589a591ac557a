#include "common/stvk_force_model.h"

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <string>

namespace quiver {

StVKForceModel::StVKForceModel(const TetMesh& mesh, const std::vector<Material>& perTet)
    : vertexCount_(mesh.vertexCount()), tets_(mesh.tets), elements_(computeTetElements(mesh)) {
  if (static_cast<int>(perTet.size()) != mesh.tetCount())
    throw std::invalid_argument("StVKForceModel: need one material per tet (" + std::to_string(mesh.tetCount()) +
                                "), got " + std::to_string(perTet.size()));
  lambda_.reserve(perTet.size());
  mu_.reserve(perTet.size());
  for (const Material& m : perTet) {
    lambda_.push_back(m.lambda());
    mu_.push_back(m.mu());
  }

  // Pattern: vertices v and w couple (a 3x3 block) when they share a tet. Column 3v + j holds
  // the rows 3w + i of v's sorted neighbours w, so a block's position follows from w's rank.
  std::vector<std::vector<int>> neighbours(vertexCount_);
  for (const Tet& tet : tets_)
    for (int b = 0; b < 4; ++b)
      for (int a = 0; a < 4; ++a) neighbours[tet[b]].push_back(tet[a]);
  long long nonZeros = 0;
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    nonZeros += 9 * static_cast<long long>(list.size());
  }
  if (nonZeros > INT_MAX) throw std::invalid_argument("StVKForceModel: stiffness matrix too large for int indices");

  const int n = dofCount();
  std::vector<int> outer(n + 1, 0), inner(nonZeros);
  for (int v = 0; v < vertexCount_; ++v)
    for (int j = 0; j < 3; ++j) {
      int k = outer[3 * v + j];
      for (int w : neighbours[v])
        for (int i = 0; i < 3; ++i) inner[k++] = 3 * w + i;
      outer[3 * v + j + 1] = k;
    }
  std::vector<double> zeros(nonZeros, 0.0);
  pattern_ = Eigen::Map<Eigen::SparseMatrix<double>>(n, n, static_cast<Eigen::Index>(nonZeros), outer.data(),
                                                     inner.data(), zeros.data());

  slots_.resize(144 * tets_.size());
  for (size_t t = 0; t < tets_.size(); ++t) {
    const Tet& tet = tets_[t];
    int* slot = &slots_[144 * t];
    for (int b = 0; b < 4; ++b) {
      const std::vector<int>& column = neighbours[tet[b]];
      for (int j = 0; j < 3; ++j)
        for (int a = 0; a < 4; ++a) {
          const int rank = static_cast<int>(std::lower_bound(column.begin(), column.end(), tet[a]) - column.begin());
          for (int i = 0; i < 3; ++i) *slot++ = outer[3 * tet[b] + j] + 3 * rank + i;
        }
    }
  }
}

void StVKForceModel::checkSize(const Eigen::VectorXd& u) const {
  if (u.size() != dofCount())
    throw std::invalid_argument("StVKForceModel: displacement has " + std::to_string(u.size()) + " entries, expected " +
                                std::to_string(dofCount()));
}

double StVKForceModel::energy(const Eigen::VectorXd& u) const {
  checkSize(u);
  double sum = 0;
  for (size_t t = 0; t < tets_.size(); ++t) {
    const Eigen::Matrix3d H = displacementGradient(tetDisplacements(tets_[t], u), elements_.gradients[t]);
    sum += elements_.volume[t] * stvkEnergyDensity(greenStrain(H), lambda_[t], mu_[t]);
  }
  return sum;
}

void StVKForceModel::internalForce(const Eigen::VectorXd& u, Eigen::VectorXd& f) const {
  checkSize(u);
  f.setZero(dofCount());
  for (size_t t = 0; t < tets_.size(); ++t) {
    const Matrix34& G = elements_.gradients[t];
    const Eigen::Matrix3d H = displacementGradient(tetDisplacements(tets_[t], u), G);
    const Matrix34 fe = stvkElementForce(H, G, elements_.volume[t], lambda_[t], mu_[t]);
    for (int a = 0; a < 4; ++a) f.segment<3>(3 * tets_[t][a]) += fe.col(a);
  }
}

void StVKForceModel::forceHessianAtRest(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                        Eigen::VectorXd& out) const {
  checkSize(a);
  checkSize(b);
  out.setZero(dofCount());
  for (size_t t = 0; t < tets_.size(); ++t) {
    const Matrix34 fe = stvkElementForceHessianAtRest(tetDisplacements(tets_[t], a), tetDisplacements(tets_[t], b),
                                                      elements_.gradients[t], elements_.volume[t], lambda_[t], mu_[t]);
    for (int c = 0; c < 4; ++c) out.segment<3>(3 * tets_[t][c]) += fe.col(c);
  }
}

Eigen::SparseMatrix<double> StVKForceModel::tangentStiffness(const Eigen::VectorXd& u) const {
  Eigen::SparseMatrix<double> K = pattern_;
  tangentStiffness(u, K);
  return K;
}

void StVKForceModel::tangentStiffness(const Eigen::VectorXd& u, Eigen::SparseMatrix<double>& K) const {
  checkSize(u);
  if (K.rows() != pattern_.rows() || K.cols() != pattern_.cols() || !K.isCompressed() ||
      K.nonZeros() != pattern_.nonZeros())
    K = pattern_;
  double* values = K.valuePtr();
  std::fill(values, values + K.nonZeros(), 0.0);

  for (size_t t = 0; t < tets_.size(); ++t) {
    const Matrix34& G = elements_.gradients[t];
    const Eigen::Matrix3d H = displacementGradient(tetDisplacements(tets_[t], u), G);
    const Matrix12 Ke = stvkElementTangent(H, G, elements_.volume[t], lambda_[t], mu_[t]);
    const int* slot = &slots_[144 * t];
    for (int k = 0; k < 144; ++k) values[slot[k]] += Ke.data()[k];
  }
}

} // namespace quiver
