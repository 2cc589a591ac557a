#pragma once
// In-place Cholesky solves of the small dense r x r systems of implicit time stepping, with no
// allocation (a system that large compression made indefinite is the minimising solver's, which
// shifts it).
#include <cmath>
#include <cstddef>

namespace quiver::rt {

// Factorises symmetric positive definite A = U^T U in place (row-major, n x n; only its upper
// triangle is read and overwritten by U). Returns false, leaving A spoiled, when A is not positive
// definite. Right-looking, row by row: the inner loops are axpys along a row, which vectorise
// without reordering any sum (choleskyFactorLanes(), cholesky_lanes.h, does the same operations in
// the same order for a group of matrices).
inline bool choleskyFactor(double* A, int n) {
  for (int j = 0; j < n; ++j) {
    double* rowJ = A + j * n;
    if (!(rowJ[j] > 0)) return false;
    const double u = std::sqrt(rowJ[j]), inverse = 1 / u;
    rowJ[j] = u;
    for (int k = j + 1; k < n; ++k) rowJ[k] *= inverse;
    for (int i = j + 1; i < n; ++i) {
      double* rowI = A + i * n;
      const double f = rowJ[i];
      for (int k = i; k < n; ++k) rowI[k] -= f * rowJ[k];
    }
  }
  return true;
}

// A row-major factor as choleskySubstitute() reads it: entry (i, k), k >= i, at row(i)[k * kStride].
struct DenseFactor {
  static constexpr int kStride = 1;
  const double* U;
  int n;
  const double* row(int i) const { return U + i * n; }
};

// Solves U^T U x = b with the factor U of choleskyFactor() (or of choleskyFactorLanes(), read in
// place: LaneFactor, cholesky_lanes.h; the same operations in the same order); b is overwritten
// by x.
template <class Factor>
inline void choleskySubstitute(const Factor& U, double* b, int n) {
  constexpr int S = Factor::kStride;
  for (int i = 0; i < n; ++i) {  // U^T y = b
    const double* rowI = U.row(i);
    b[i] /= rowI[i * S];
    for (int k = i + 1; k < n; ++k) b[k] -= rowI[k * S] * b[i];
  }
  for (int i = n - 1; i >= 0; --i) {  // U x = y
    const double* rowI = U.row(i);
    double s = b[i];
    for (int k = i + 1; k < n; ++k) s -= rowI[k * S] * b[k];
    b[i] = s / rowI[i * S];
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

} // namespace quiver::rt
