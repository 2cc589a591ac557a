#include "cholesky_lanes.h"

#include <cmath>

#include "simd_dispatch.h"

namespace quiver::rt {

namespace {

// The pivots' square roots in place, and their inverses: a lane that failed (d <= 0) goes on with a
// unit pivot, finite and ignored. A loop of its own: inside the factorisation's loops GCC left it
// scalar, with a sqrt and a division in series per lane (a tenth of a group's factorisation).
QV_HOT void pivots(double* d, double* inverse) {
#pragma omp simd
  for (int l = 0; l < kCholeskyLanes; ++l) {
    const double u = std::sqrt(d[l] > 0 ? d[l] : 1.0);
    d[l] = u;
    inverse[l] = 1 / u;
  }
}

} // namespace

QV_HOT void choleskyFactorLanes(double* A, int n, bool* ok) {
  constexpr int L = kCholeskyLanes, B = 4;
  // row(i) + j * L: entry (i, j), j >= i.
  const auto row = [&](int i) { return A + (packedUpperIndex(n, i, i) - static_cast<size_t>(i)) * L; };
  for (int l = 0; l < L; ++l) ok[l] = true;
  // choleskyFactor()'s panels of four pivots: one load and store of each entry below a panel for
  // its four updates (a sweep per pivot stored each entry once per pivot: the stores bound it).
  for (int j = 0; j < n; j += B) {
    const int end = j + B < n ? j + B : n;
    for (int t = j; t < end; ++t) {
      double* rowT = row(t);
      double inverse[L];
      for (int l = 0; l < L; ++l) ok[l] = ok[l] && rowT[t * L + l] > 0;
      pivots(rowT + t * L, inverse);
      for (int k = t + 1; k < n; ++k)
#pragma omp simd
        for (int l = 0; l < L; ++l) rowT[k * L + l] *= inverse[l];
      for (int i = t + 1; i < end; ++i) {
        double* rowI = row(i);
        const double* f = rowT + i * L;
        for (int k = i; k < n; ++k)
#pragma omp simd
          for (int l = 0; l < L; ++l) rowI[k * L + l] -= f[l] * rowT[k * L + l];
      }
    }
    if (end - j < B) break;  // the last panel: no rows below it
    const double *r0 = row(j), *r1 = row(j + 1), *r2 = row(j + 2), *r3 = row(j + 3);
    for (int i = end; i < n; ++i) {
      double* rowI = row(i);
      const double *f0 = r0 + i * L, *f1 = r1 + i * L, *f2 = r2 + i * L, *f3 = r3 + i * L;
      for (int k = i; k < n; ++k)
#pragma omp simd
        for (int l = 0; l < L; ++l) {
          double a = rowI[k * L + l];
          a -= f0[l] * r0[k * L + l];
          a -= f1[l] * r1[k * L + l];
          a -= f2[l] * r2[k * L + l];
          a -= f3[l] * r3[k * L + l];
          rowI[k * L + l] = a;
        }
    }
  }
}

} // namespace quiver::rt
