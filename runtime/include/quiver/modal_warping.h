#pragma once
// Modal warping (Choi & Ko 2005), the meaning of the .qvr's MODAL_ROTATIONS: a vertex whose linear
// displacement is d and whose small rotation is w (w = Psi_v q in a subspace, or 1/2 curl u in full
// space) is moved by the rotation grown from 0 to w along the deformation, integrated:
//   u = (I + (1 - cos t)/t^2 [w]x + (t - sin t)/t^3 [w]x^2) d,   t = |w|,
// which tends to d for small w and keeps lengths when d is itself the linear image w x X of a
// rotation. Header-only C++, standard library only: the runtime steps with it, the full-space
// reference (common/) warps with the same formula, and an engine that warps on its own (in a
// shader, say) can include it.
#include <cmath>

namespace quiver::warping {

inline void cross3(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// Rotates v by the finite rotation of angle |w| about w (Rodrigues).
inline void rotate(const double w[3], const double v[3], double out[3]) {
  const double angle = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  if (!(angle > 0)) {
    for (int c = 0; c < 3; ++c) out[c] = v[c];
    return;
  }
  const double axis[3] = {w[0] / angle, w[1] / angle, w[2] / angle};
  double c1[3], c2[3];
  cross3(axis, v, c1);
  cross3(axis, c1, c2);
  for (int c = 0; c < 3; ++c) out[c] = v[c] + std::sin(angle) * c1[c] + (1 - std::cos(angle)) * c2[c];
}

inline void warpDisplacement(const double w[3], const double linear[3], double out[3]) {
  const double t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], t = std::sqrt(t2);
  // Series near 0, where the closed forms lose their digits.
  const double a = t < 1e-4 ? 0.5 - t2 / 24 : (1 - std::cos(t)) / t2;
  const double b = t < 1e-4 ? 1.0 / 6 - t2 / 120 : (t - std::sin(t)) / (t2 * t);
  double wx[3], wwx[3];
  cross3(w, linear, wx);
  cross3(w, wx, wwx);
  for (int c = 0; c < 3; ++c) out[c] = linear[c] + a * wx[c] + b * wwx[c];
}

} // namespace quiver::warping
