#pragma once
// Vectors of three doubles and 3 x 3 matrices (row-major) as plain arrays: the frames', the
// contacts' and the colliders' geometry.
#include <cmath>

namespace quiver::rt {

inline double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

inline double norm3(const double a[3]) { return std::sqrt(dot3(a, a)); }

inline void cross3(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// out = A v.
inline void multiply3(const double A[9], const double v[3], double out[3]) {
  for (int a = 0; a < 3; ++a) out[a] = A[3 * a] * v[0] + A[3 * a + 1] * v[1] + A[3 * a + 2] * v[2];
}

// out = A^T v.
inline void multiplyTransposed3(const double A[9], const double v[3], double out[3]) {
  for (int a = 0; a < 3; ++a) out[a] = A[a] * v[0] + A[3 + a] * v[1] + A[6 + a] * v[2];
}

} // namespace quiver::rt
