#include "common/stvk_element.h"

namespace quiver {

Eigen::Matrix3d greenStrain(const Eigen::Matrix3d& H) { return 0.5 * (H + H.transpose() + H.transpose() * H); }

Eigen::Matrix3d stvkSecondPiolaKirchhoff(const Eigen::Matrix3d& E, double lambda, double mu) {
  return 2 * mu * E + lambda * E.trace() * Eigen::Matrix3d::Identity();
}

double stvkEnergyDensity(const Eigen::Matrix3d& E, double lambda, double mu) {
  const double trace = E.trace();
  return mu * E.squaredNorm() + 0.5 * lambda * trace * trace;
}

Matrix34 stvkElementForce(const Eigen::Matrix3d& H, const Matrix34& G, double V, double lambda, double mu) {
  const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + H;
  return V * F * stvkSecondPiolaKirchhoff(greenStrain(H), lambda, mu) * G;
}

Matrix12 stvkElementTangent(const Eigen::Matrix3d& H, const Matrix34& G, double V, double lambda, double mu) {
  const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + H;
  const Eigen::Matrix3d S = stvkSecondPiolaKirchhoff(greenStrain(H), lambda, mu);
  // Differentiating V P g_a = V F S g_a along u_b gives a geometric term (S fixed, F moves)
  // and a material term (S moves with E); both reduce to these small products.
  const Eigen::Matrix4d GSG = G.transpose() * S * G;
  const Eigen::Matrix4d GG = G.transpose() * G;
  const Eigen::Matrix3d B = F * F.transpose();
  const Matrix34 A = F * G;  // column a: F g_a
  Matrix12 K;
  for (int a = 0; a < 4; ++a)
    for (int b = a; b < 4; ++b) {
      const Eigen::Matrix3d block = V * (GSG(a, b) * Eigen::Matrix3d::Identity() + mu * GG(a, b) * B +
                                         mu * A.col(b) * A.col(a).transpose() + lambda * A.col(a) * A.col(b).transpose());
      K.block<3, 3>(3 * a, 3 * b) = block;
      if (b != a) K.block<3, 3>(3 * b, 3 * a) = block.transpose();
    }
  return K;
}

RestDirection stvkRestDirection(const Matrix34& a, const Matrix34& G, double lambda, double mu) {
  RestDirection d;
  d.H = a * G.transpose();
  d.dS = mu * (d.H + d.H.transpose()) + lambda * d.H.trace() * Eigen::Matrix3d::Identity();
  return d;
}

Matrix34 stvkElementForceHessianAtRest(const RestDirection& a, const RestDirection& b, const Matrix34& G, double V,
                                       double lambda, double mu) {
  const Eigen::Matrix3d HaHb = a.H.transpose() * b.H;
  const Eigen::Matrix3d d2S = mu * (HaHb + HaHb.transpose()) + lambda * HaHb.trace() * Eigen::Matrix3d::Identity();
  return V * (a.H * b.dS + b.H * a.dS + d2S) * G;
}

Matrix34 stvkElementForceHessianAtRest(const Matrix34& a, const Matrix34& b, const Matrix34& G, double V,
                                       double lambda, double mu) {
  return stvkElementForceHessianAtRest(stvkRestDirection(a, G, lambda, mu), stvkRestDirection(b, G, lambda, mu), G, V,
                                       lambda, mu);
}

} // namespace quiver
