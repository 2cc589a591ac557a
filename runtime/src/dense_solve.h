#pragma once
// In-place Cholesky solves of the small dense r x r systems of implicit time stepping, with no
// allocation (a system that large compression made indefinite is the minimising solver's, which
// shifts it).
#include <cmath>
#include <cstddef>

namespace quiver::rt {

// Factorises symmetric positive definite A = U^T U in place (row-major, n x n; only its upper
// triangle is read and overwritten by U). Returns false, leaving A spoiled, when A is not positive
// definite. Right-looking, row by row: each pivot row j is scaled, then subtracted from the rows
// below it, as axpys along a row, which vectorise without reordering any sum
// (choleskyFactorLanes(), cholesky_lanes.h, does the same operations in the same order for a group
// of matrices). Pivots are taken four at a time: the panel's rows first, then every row below
// takes the four pivots' updates in one sweep, each entry in pivot order (the same operations in
// the same order as one sweep per pivot, with a quarter of the loads, stores and short loops).
inline bool choleskyFactor(double* A, int n) {
  constexpr int B = 4;
  for (int j = 0; j < n; j += B) {
    const int end = j + B < n ? j + B : n;
    for (int t = j; t < end; ++t) {
      double* rowT = A + t * n;
      if (!(rowT[t] > 0)) return false;
      const double u = std::sqrt(rowT[t]), inverse = 1 / u;
      rowT[t] = u;
      for (int k = t + 1; k < n; ++k) rowT[k] *= inverse;
      for (int i = t + 1; i < end; ++i) {
        double* rowI = A + i * n;
        const double f = rowT[i];
        for (int k = i; k < n; ++k) rowI[k] -= f * rowT[k];
      }
    }
    if (end - j < B) break;  // the last panel: no rows below it
    const double *r0 = A + j * n, *r1 = r0 + n, *r2 = r1 + n, *r3 = r2 + n;
    for (int i = end; i < n; ++i) {
      double* rowI = A + i * n;
      const double f0 = r0[i], f1 = r1[i], f2 = r2[i], f3 = r3[i];
      for (int k = i; k < n; ++k) {
        double a = rowI[k];
        a -= f0 * r0[k];
        a -= f1 * r1[k];
        a -= f2 * r2[k];
        a -= f3 * r3[k];
        rowI[k] = a;
      }
    }
  }
  return true;
}

// A row-major factor as choleskySubstitute() reads it: entry (i, k), k >= i, at row(i)[k * kStride].
struct DenseFactor {
  static constexpr int kStride = 1;
  using Value = double;
  const double* U;
  int n;
  const double* row(int i) const { return U + i * n; }
  static void load(const double* at, double& value) { value = *at; }
};

// Solves U^T U x = b with the factor U of choleskyFactor() (or of choleskyFactorLanes(), read in
// place: LaneFactor, cholesky_lanes.h; the same operations in the same order); b is overwritten
// by x. Factor::Value is what one entry is: a double, or a vector of four lanes' (LanesFactor: a
// group's systems four at a time, each lane's operations those of its own solve). The second
// half's dot products run as four interleaved sums: one sum waited on the multiply-add's latency
// at every term (two fifths of a crowd member's solve).
template <class Factor>
inline void choleskySubstitute(const Factor& U, typename Factor::Value* b, int n) {
  using T = typename Factor::Value;
  constexpr int S = Factor::kStride;
  T u;
  for (int i = 0; i < n; ++i) {  // U^T y = b
    const double* rowI = U.row(i);
    Factor::load(rowI + i * S, u);
    b[i] /= u;
    for (int k = i + 1; k < n; ++k) {
      Factor::load(rowI + k * S, u);
      b[k] -= u * b[i];
    }
  }
  for (int i = n - 1; i >= 0; --i) {  // U x = y
    const double* rowI = U.row(i);
    T s[4] = {};
    int k = i + 1;
    for (; k + 4 <= n; k += 4)
      for (int m = 0; m < 4; ++m) {
        Factor::load(rowI + (k + m) * S, u);
        s[m] += u * b[k + m];
      }
    for (int m = 0; k < n; ++k, ++m) {
      Factor::load(rowI + k * S, u);
      s[m] += u * b[k];
    }
    Factor::load(rowI + i * S, u);
    b[i] = (b[i] - ((s[0] + s[1]) + (s[2] + s[3]))) / u;
  }
}

// Solves A x = b for symmetric positive definite A (as choleskyFactor(): A is overwritten by its
// factor); b is overwritten by x. Returns false, leaving A spoiled and b as it was, when A is not
// positive definite.
inline bool choleskySolve(double* A, double* b, int n) {
  if (!choleskyFactor(A, n)) return false;
  choleskySubstitute(DenseFactor{A, n}, b, n);
  return true;
}

// Diagonalises symmetric A = V diag(lambda) V^T (row-major, n x n) by cyclic Jacobi rotations:
// A is overwritten (its diagonal ends as lambda), V (n x n, row-major) receives the eigenvectors
// as columns. Accurate to rounding for the small matrices a model loads once (K(0), r x r).
inline void symmetricEigen(double* A, double* V, int n) {
  for (int i = 0; i < n * n; ++i) V[i] = i % (n + 1) == 0 ? 1.0 : 0.0;
  for (int sweep = 0; sweep < 64; ++sweep) {
    double off = 0, diagonal = 0;
    for (int i = 0; i < n; ++i) {
      diagonal += A[i * n + i] * A[i * n + i];
      for (int j = i + 1; j < n; ++j) off += A[i * n + j] * A[i * n + j];
    }
    if (!(off > 1e-32 * diagonal)) return;  // converged (or not finite: nothing better to do)
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) {
        const double apq = A[p * n + q];
        if (apq == 0) continue;
        // The rotation (c, s) that zeroes A[p][q]: t = tan of its angle, the smaller root.
        const double theta = (A[q * n + q] - A[p * n + p]) / (2 * apq);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < n; ++k) {  // columns p and q: A <- A J
          const double akp = A[k * n + p], akq = A[k * n + q];
          A[k * n + p] = c * akp - s * akq, A[k * n + q] = s * akp + c * akq;
        }
        for (int k = 0; k < n; ++k) {  // rows p and q: A <- J^T A
          const double apk = A[p * n + k], aqk = A[q * n + k];
          A[p * n + k] = c * apk - s * aqk, A[q * n + k] = s * apk + c * aqk;
        }
        for (int k = 0; k < n; ++k) {  // V <- V J
          const double vkp = V[k * n + p], vkq = V[k * n + q];
          V[k * n + p] = c * vkp - s * vkq, V[k * n + q] = s * vkp + c * vkq;
        }
      }
  }
}

} // namespace quiver::rt
