#include "precompute/stages/polynomials.h"

#include <algorithm>
#include <array>

#include <Eigen/Cholesky>
#include <cblas.h>

#include "common/tet_elements.h"
#include "formats/model/qvr.h"

namespace quiver {

namespace {

// Symmetric 3x3 as the 6-vector (xx, yy, zz, yz, xz, xy), scaled by `s`.
inline void voigt(const Eigen::Matrix3d& A, double s, double* out) {
  out[0] = s * A(0, 0);
  out[1] = s * A(1, 1);
  out[2] = s * A(2, 2);
  out[3] = s * 0.5 * (A(1, 2) + A(2, 1));
  out[4] = s * 0.5 * (A(0, 2) + A(2, 0));
  out[5] = s * 0.5 * (A(0, 1) + A(1, 0));
}

// C with C^T C = V (\mu W + \tfrac{\lambda}{2} t t^T): the normal block is dense, the shear block diagonal.
Eigen::Matrix<double, 6, 6> energyFactor(double V, double lambda, double mu) {
  Eigen::Matrix3d normal = V * (mu * Eigen::Matrix3d::Identity() + 0.5 * lambda * Eigen::Matrix3d::Ones());
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  C.topLeftCorner<3, 3>() = normal.llt().matrixU();
  C.bottomRightCorner<3, 3>().diagonal().setConstant(std::sqrt(2 * mu * V));
  return C;
}

// Writes tet t's six rows of B = C [L S] into the column-major block `B` (leading dimension ld).
void tetRows(const Eigen::MatrixXd& U, const Tet& tet, const Matrix34& grad, const Eigen::Matrix<double, 6, 6>& C,
             int r, double* B, int64_t ld, std::vector<Eigen::Matrix3d>& G, Eigen::Matrix<double, 6, Eigen::Dynamic>& LS) {
  // G and LS are scratch the caller owns, so that the loop over tets does not allocate.
  for (int j = 0; j < r; ++j) {
    Matrix34 Ue;
    for (int a = 0; a < 4; ++a) Ue.col(a) = U.block<3, 1>(3 * tet[a], j);
    G[j] = Ue * grad.transpose();
  }
  for (int j = 0; j < r; ++j) voigt(G[j], 1.0, LS.col(j).data());
  int column = r;
  for (int j = 0; j < r; ++j)
    for (int k = j; k < r; ++k) voigt(G[j].transpose() * G[k], j == k ? 0.5 : 1.0, LS.col(column++).data());
  Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic>, 0, Eigen::OuterStride<>> rows(B, 6, LS.cols(),
                                                                                    Eigen::OuterStride<>(ld));
  rows.noalias() = C.triangularView<Eigen::Upper>() * LS;
}

// Monomial coefficients of q^T A2 q + 2 q^T A3 z + z^T A4 z from the upper triangle of the Gram
// matrix [A2 A3; A3^T A4].
std::vector<double> monomialCoefficients(const Eigen::MatrixXd& gram, int r) {
  const int64_t c2 = monomialCount2(r), c3 = monomialCount3(r), c4 = monomialCount4(r);
  std::vector<double> out(c2 + c3 + c4, 0.0);
  double* d2 = out.data();
  double* d3 = d2 + c2;
  double* d4 = d3 + c3;
  std::vector<std::array<int, 2>> pair;
  for (int j = 0; j < r; ++j)
    for (int k = j; k < r; ++k) pair.push_back({j, k});
  const int P = static_cast<int>(pair.size());
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j) d2[monomialIndex2(r, i, j)] += (i == j ? 1.0 : 2.0) * gram(i, j);
  for (int i = 0; i < r; ++i)
    for (int p = 0; p < P; ++p) {
      std::array<int, 3> m{i, pair[p][0], pair[p][1]};
      std::sort(m.begin(), m.end());
      d3[monomialIndex3(r, m[0], m[1], m[2])] += 2.0 * gram(i, r + p);
    }
  for (int p = 0; p < P; ++p)
    for (int s = p; s < P; ++s) {
      std::array<int, 4> m{pair[p][0], pair[p][1], pair[s][0], pair[s][1]};
      std::sort(m.begin(), m.end());
      d4[monomialIndex4(r, m[0], m[1], m[2], m[3])] += (p == s ? 1.0 : 2.0) * gram(r + p, r + s);
    }
  return out;
}

} // namespace

EnergyPolynomial computeEnergyPolynomial(MPI_Comm comm, const TetMesh& mesh, const std::vector<Material>& perTet,
                                         const std::vector<int>& tetPart, const Eigen::MatrixXd& basis,
                                         const PolynomialSettings& settings) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const int r = static_cast<int>(basis.cols());
  const int N = r + r * (r + 1) / 2;
  std::vector<int> mine;
  for (int t = 0; t < mesh.tetCount(); ++t)
    if (tetPart[t] == rank) mine.push_back(t);

  const TetElements elements = computeTetElements(mesh);
  const int block = std::max(1, settings.tetsPerBlock);
  const int64_t ld = 6 * static_cast<int64_t>(block);
  std::vector<double> B(static_cast<size_t>(ld) * N);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(N, N);
  std::vector<Eigen::Matrix3d> G(r);
  Eigen::Matrix<double, 6, Eigen::Dynamic> LS(6, N);
  for (size_t first = 0; first < mine.size(); first += block) {
    const int count = static_cast<int>(std::min<size_t>(block, mine.size() - first));
    for (int b = 0; b < count; ++b) {
      const int t = mine[first + b];
      const Material& m = perTet[t];
      tetRows(basis, mesh.tets[t], elements.gradients[t], energyFactor(elements.volume[t], m.lambda(), m.mu()), r,
              B.data() + 6 * b, ld, G, LS);
    }
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, N, 6 * count, 1.0, B.data(), static_cast<int>(ld), 1.0,
                gram.data(), N);
    if (settings.progress) settings.progress(static_cast<int64_t>(first + count), static_cast<int64_t>(mine.size()));
  }
  EnergyPolynomial out;
  out.r = r;
  const std::vector<double> local = monomialCoefficients(gram, r);
  out.coefficients.resize(local.size());
  MPI_Allreduce(local.data(), out.coefficients.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, comm);
  return out;
}

} // namespace quiver
