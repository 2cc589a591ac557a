#include "common/stvk_element.h"

#include <vector>

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

namespace {

// \delta S along a direction whose displacement gradient is H.
Eigen::Matrix3d deltaS(const Eigen::Matrix3d& H, double lambda, double mu) {
  return mu * (H + H.transpose()) + lambda * H.trace() * Eigen::Matrix3d::Identity();
}

} // namespace

Matrix34 stvkElementForceHessianAtRest(const Matrix34& a, const Matrix34& b, const Matrix34& G, double V,
                                       double lambda, double mu) {
  const Eigen::Matrix3d Ha = a * G.transpose(), Hb = b * G.transpose();
  const Eigen::Matrix3d HaHb = Ha.transpose() * Hb;
  const Eigen::Matrix3d d2S = mu * (HaHb + HaHb.transpose()) + lambda * HaHb.trace() * Eigen::Matrix3d::Identity();
  return V * (Ha * deltaS(Hb, lambda, mu) + Hb * deltaS(Ha, lambda, mu) + d2S) * G;
}

void stvkElementForceHessiansAtRest(const Eigen::Matrix<double, 3, Eigen::Dynamic>& directions, const Matrix34& G,
                                    double V, double lambda, double mu, double* out, Eigen::Index ld) {
  const Eigen::Index k = directions.cols() / 4;
  // Entry e (column-major) of direction j's H at h[e * k + j], of its \delta S at s[e * k + j].
  std::vector<double> h(9 * k), s(9 * k);
  for (Eigen::Index j = 0; j < k; ++j) {
    const Eigen::Matrix3d H = directions.middleCols<4>(4 * j) * G.transpose();
    const Eigen::Matrix3d dS = deltaS(H, lambda, mu);
    for (int e = 0; e < 9; ++e) {
      h[e * k + j] = H(e);
      s[e * k + j] = dS(e);
    }
  }
  for (Eigen::Index i = 0, p = 0; i < k; p += k - i, ++i) {
    double ha[9], sa[9];
    for (int e = 0; e < 9; ++e) {
      ha[e] = h[e * k + i];
      sa[e] = s[e * k + i];
    }
#if defined(__GNUC__) && !defined(__clang__)  // clang warns of a pragma it does not know
#pragma GCC ivdep  // `out` is none of the arrays read: vectorise across j (1.4x)
#endif
    for (Eigen::Index j = i; j < k; ++j) {
      double hb[9], sb[9];
      for (int e = 0; e < 9; ++e) {
        hb[e] = h[e * k + j];
        sb[e] = s[e * k + j];
      }
      double hh[9];  // H_a^T H_b
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) hh[r + 3 * c] = ha[3 * r] * hb[3 * c] + ha[3 * r + 1] * hb[3 * c + 1] + ha[3 * r + 2] * hb[3 * c + 2];
      const double trace = hh[0] + hh[4] + hh[8];
      double m[9];  // V d^2P
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          m[r + 3 * c] = V * ((ha[r] * sb[3 * c] + ha[r + 3] * sb[3 * c + 1] + ha[r + 6] * sb[3 * c + 2]) +
                              (hb[r] * sa[3 * c] + hb[r + 3] * sa[3 * c + 1] + hb[r + 6] * sa[3 * c + 2]) +
                              (mu * (hh[r + 3 * c] + hh[c + 3 * r]) + (r == c ? lambda * trace : 0.0)));
      for (int v = 0; v < 4; ++v)
        for (int r = 0; r < 3; ++r)
          out[(3 * v + r) * ld + p + (j - i)] = m[r] * G(0, v) + m[r + 3] * G(1, v) + m[r + 6] * G(2, v);
    }
  }
}

} // namespace quiver
