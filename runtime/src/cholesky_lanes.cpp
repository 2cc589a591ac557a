#include "cholesky_lanes.h"

#include <cmath>

#include "simd_dispatch.h"

namespace quiver::rt {

QV_HOT void choleskyFactorLanes(double* A, int n, bool* ok) {
  constexpr int L = kCholeskyLanes;
  // row(i) + j * L: entry (i, j), j >= i.
  const auto row = [&](int i) { return A + (packedUpperIndex(n, i, i) - static_cast<size_t>(i)) * L; };
  for (int l = 0; l < L; ++l) ok[l] = true;
  for (int j = 0; j < n; ++j) {
    double* rowJ = row(j);
    double inverse[L];
#pragma omp simd
    for (int l = 0; l < L; ++l) {
      const double d = rowJ[j * L + l];
      const bool positive = d > 0;
      ok[l] = ok[l] && positive;
      // A lane that failed goes on with a unit pivot: finite, and ignored.
      const double u = std::sqrt(positive ? d : 1.0);
      rowJ[j * L + l] = u;
      inverse[l] = 1 / u;
    }
    for (int k = j + 1; k < n; ++k)
#pragma omp simd
      for (int l = 0; l < L; ++l) rowJ[k * L + l] *= inverse[l];
    for (int i = j + 1; i < n; ++i) {
      double* rowI = row(i);
      const double* f = rowJ + i * L;
      for (int k = i; k < n; ++k)
#pragma omp simd
        for (int l = 0; l < L; ++l) rowI[k * L + l] -= f[l] * rowJ[k * L + l];
    }
  }
}

} // namespace quiver::rt
