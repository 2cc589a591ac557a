#include "rigid_frame.h"

#include <cmath>
#include <cstring>

namespace quiver::rt {

namespace {

// The RIGID_BODY moments of the model (formats/model/QVR.md): c, S0, B (9 x r), A (9 blocks r x r).
struct Moments {
  const double* centre;
  const double* S0;
  const double* B;
  const double* A;
  explicit Moments(const qv_model& m)
      : centre(m.rigidBody), S0(m.rigidBody + 3), B(m.rigidBody + 12), A(m.rigidBody + 12 + 9 * m.info.r) {}
};

// Levi-Civita symbol e_abc.
double epsilon(int a, int b, int c) { return 0.5 * (a - b) * (b - c) * (c - a); }

void rotate(const double R[9], const double v[3], double out[3]) {
  for (int a = 0; a < 3; ++a) out[a] = R[3 * a] * v[0] + R[3 * a + 1] * v[1] + R[3 * a + 2] * v[2];
}

void rotateBack(const double R[9], const double v[3], double out[3]) {
  for (int a = 0; a < 3; ++a) out[a] = R[a] * v[0] + R[3 + a] * v[1] + R[6 + a] * v[2];
}

// x = S^-1 b for a symmetric positive definite 3 x 3 S, by its adjugate.
void solve3(const double S[9], const double b[3], double x[3]) {
  const double c00 = S[4] * S[8] - S[5] * S[7], c01 = S[5] * S[6] - S[3] * S[8], c02 = S[3] * S[7] - S[4] * S[6];
  const double c11 = S[0] * S[8] - S[2] * S[6], c12 = S[2] * S[3] - S[0] * S[5], c22 = S[0] * S[4] - S[1] * S[3];
  const double det = S[0] * c00 + S[1] * c01 + S[2] * c02;
  x[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) / det;
  x[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) / det;
  x[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) / det;
}

double dot(const double* a, const double* b, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

} // namespace

void RigidFrame::attach(double* scratch, int r) {
  moments = scratch;
  products = scratch ? scratch + 9 * static_cast<size_t>(r) : nullptr;
}

void RigidFrame::setOrientation(const double qn[4]) {
  const double len = std::sqrt(qn[0] * qn[0] + qn[1] * qn[1] + qn[2] * qn[2] + qn[3] * qn[3]);
  const double w = qn[0] / len, x = qn[1] / len, y = qn[2] / len, z = qn[3] / len;
  orientation[0] = w, orientation[1] = x, orientation[2] = y, orientation[3] = z;
  const double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                       2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                       2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
  std::memcpy(rotation, R, sizeof R);
}

void RigidFrame::refresh(const qv_model& model, const double* q, const double* qdot) {
  const int r = model.info.r;
  const Moments mo(model);
  // y_ab = B_ab + A_ba q, A_ba = \int rho U_b U_a^T.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double* Bab = mo.B + (3 * a + b) * static_cast<size_t>(r);
      const double* Aba = mo.A + (3 * b + a) * static_cast<size_t>(r) * r;
      double* y = moments + (3 * a + b) * static_cast<size_t>(r);
      for (int j = 0; j < r; ++j) y[j] = Bab[j] + dot(Aba + static_cast<size_t>(j) * r, q, r);
    }
  // S_ab = S0_ab + B_ba q + y_ab q; I = tr(S) 1 - S; h_c = e_cab y_ab q'.
  double S[9];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      S[3 * a + b] = mo.S0[3 * a + b] + dot(mo.B + (3 * b + a) * static_cast<size_t>(r), q, r) +
                     dot(moments + (3 * a + b) * static_cast<size_t>(r), q, r);
  const double trace = S[0] + S[4] + S[8];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) inertia[3 * a + b] = (a == b ? trace : 0.0) - 0.5 * (S[3 * a + b] + S[3 * b + a]);
  for (int c = 0; c < 3; ++c) {
    internal[c] = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (a != b && a != c && b != c) internal[c] += epsilon(c, a, b) * dot(moments + (3 * a + b) * static_cast<size_t>(r), qdot, r);
  }
  double bodyL[3];
  rotateBack(rotation, angularMomentum, bodyL);
  for (int c = 0; c < 3; ++c) bodyL[c] -= internal[c];
  solve3(inertia, bodyL, bodyOmega);
}

void RigidFrame::worldOmega(double omega[3]) const { rotate(rotation, bodyOmega, omega); }

void RigidFrame::setWorldOmega(const double omega[3]) {
  rotateBack(rotation, omega, bodyOmega);
  double bodyL[3];
  for (int a = 0; a < 3; ++a) bodyL[a] = dot(inertia + 3 * a, bodyOmega, 3) + internal[a];
  rotate(rotation, bodyL, angularMomentum);
  std::memcpy(lastBodyOmega, bodyOmega, sizeof bodyOmega);
}

void RigidFrame::holdSpin() {
  rotateBack(rotation, angularMomentum, heldMomentum);
  for (int c = 0; c < 3; ++c) heldMomentum[c] -= internal[c];
}

double RigidFrame::addCentrifugal(const qv_model& model, const double* q, double* resisting, double* jacobian) const {
  const int r = model.info.r;
  const size_t rr = static_cast<size_t>(r) * r;
  const Moments mo(model);
  // S(q) = S0 + (B_ab + B_ba) q + q^T A_ab q, keeping A_ab q for the gradient.
  double S[9];
  for (int ab = 0; ab < 9; ++ab) {
    const int a = ab / 3, b = ab % 3;
    double* t = products + ab * static_cast<size_t>(r);
    for (int j = 0; j < r; ++j) t[j] = dot(mo.A + ab * rr + static_cast<size_t>(j) * r, q, r);
    S[ab] = mo.S0[ab] + dot(mo.B + ab * static_cast<size_t>(r), q, r) + dot(mo.B + (3 * b + a) * static_cast<size_t>(r), q, r) +
            dot(q, t, r);
  }
  const double trace = S[0] + S[4] + S[8];
  double I[9], w[3];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) I[3 * a + b] = (a == b ? trace : 0.0) - 0.5 * (S[3 * a + b] + S[3 * b + a]);
  solve3(I, heldMomentum, w);
  // dV/dq = -omega . (dI/dq) omega / 2 = -sum_ab W_ab (B_ab + A_ab q), W_ab = |omega|^2 d_ab - omega_a omega_b;
  // its Hessian with omega held, -sum_ab W_ab (A_ab + A_ab^T) / 2 (softening; the step shifts it).
  const double w2 = dot(w, w, 3);
  for (int ab = 0; ab < 9; ++ab) {
    const int a = ab / 3, b = ab % 3;
    const double W = (a == b ? w2 : 0.0) - w[a] * w[b];
    if (W == 0) continue;
    const double* Bab = mo.B + ab * static_cast<size_t>(r);
    const double* t = products + ab * static_cast<size_t>(r);
    const double* A = mo.A + ab * rr;
    for (int j = 0; j < r; ++j) {
      resisting[j] -= W * (Bab[j] + t[j]);
      for (int k = 0; k < r; ++k) jacobian[j * r + k] -= 0.5 * W * (A[j * r + k] + A[k * r + j]);
    }
  }
  return 0.5 * dot(heldMomentum, w, 3);
}

void RigidFrame::addInertialForces(const qv_model& model, double h, double* reducedForce) const {
  const int r = model.info.r;
  double wd[3];
  for (int c = 0; c < 3; ++c) wd[c] = (bodyOmega[c] - lastBodyOmega[c]) / h;
  // -U^T M (omega' x p), with (w x p)_b = e_bca w_c p_a: -e_bca omega'_c y_ab.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double c1 = 0;
      for (int c = 0; c < 3; ++c) c1 += epsilon(b, c, a) * wd[c];
      if (c1 == 0) continue;
      const double* y = moments + (3 * a + b) * static_cast<size_t>(r);
      for (int j = 0; j < r; ++j) reducedForce[j] -= c1 * y[j];
    }
}

void RigidFrame::accelerate(const qv_model& model, double h) {
  const double mass = model.info.total_mass;
  for (int a = 0; a < 3; ++a) {
    velocity[a] += h * (force[a] / mass + gravity[a]);
    angularMomentum[a] += h * torque[a];
  }
}

void RigidFrame::move(double h) {
  for (int a = 0; a < 3; ++a) position[a] += h * velocity[a];
  // R <- exp(h omega) R by the implicit midpoint rule: omega is what L gives at the midpoint
  // orientation exp(h omega / 2) R (fixed-point iterations, I(q) and h of the step's start). The
  // explicit turn (omega of the start) drifts toward the axis of least inertia, gaining energy;
  // the midpoint turn is time-symmetric and does not.
  const double start[4] = {orientation[0], orientation[1], orientation[2], orientation[3]};
  double omega[3];
  worldOmega(omega);
  for (int it = 0; it < 6; ++it) {
    turn(start, omega, 0.5 * h);
    double bodyL[3];
    rotateBack(rotation, angularMomentum, bodyL);
    for (int c = 0; c < 3; ++c) bodyL[c] -= internal[c];
    double w[3];
    solve3(inertia, bodyL, w);
    rotate(rotation, w, omega);
  }
  turn(start, omega, h);
  std::memcpy(lastBodyOmega, bodyOmega, sizeof bodyOmega);
  for (int a = 0; a < 3; ++a) force[a] = torque[a] = 0;
}

void RigidFrame::turn(const double from[4], const double omega[3], double t) {
  // The quaternion of the turn t |omega| about omega, times `from`.
  const double rate = std::sqrt(dot(omega, omega, 3)), angle = t * rate;
  if (!(angle > 0)) {
    setOrientation(from);
    return;
  }
  const double s = std::sin(0.5 * angle) / rate, c = std::cos(0.5 * angle);
  const double q[4] = {c, s * omega[0], s * omega[1], s * omega[2]};
  const double* o = from;
  const double turned[4] = {q[0] * o[0] - q[1] * o[1] - q[2] * o[2] - q[3] * o[3],
                            q[0] * o[1] + q[1] * o[0] + q[2] * o[3] - q[3] * o[2],
                            q[0] * o[2] - q[1] * o[3] + q[2] * o[0] + q[3] * o[1],
                            q[0] * o[3] + q[1] * o[2] - q[2] * o[1] + q[3] * o[0]};
  setOrientation(turned);
}

void RigidFrame::toWorld(const double p[3], double out[3]) const {
  rotate(rotation, p, out);
  for (int a = 0; a < 3; ++a) out[a] += position[a];
}

void RigidFrame::toBody(const double f[3], double out[3]) const { rotateBack(rotation, f, out); }

void RigidFrame::toWorldDirection(const double v[3], double out[3]) const { rotate(rotation, v, out); }

void RigidFrame::inverseInertia(const double w[3], double out[3]) const {
  double body[3], x[3];
  rotateBack(rotation, w, body);
  solve3(inertia, body, x);
  rotate(rotation, x, out);
}

double RigidFrame::kineticEnergy(const qv_model& model) const {
  double spin = 0;
  for (int a = 0; a < 3; ++a) spin += bodyOmega[a] * (0.5 * dot(inertia + 3 * a, bodyOmega, 3) + internal[a]);
  return 0.5 * model.info.total_mass * dot(velocity, velocity, 3) + spin;
}

void RigidFrame::goHome() {
  std::memcpy(position, homePosition, sizeof position);
  setOrientation(homeOrientation);
  for (int a = 0; a < 3; ++a) velocity[a] = angularMomentum[a] = bodyOmega[a] = lastBodyOmega[a] = force[a] = torque[a] = 0;
}

bool RigidFrame::finite() const {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(position[a]) || !std::isfinite(velocity[a]) || !std::isfinite(angularMomentum[a]) ||
        !std::isfinite(bodyOmega[a]))
      return false;
  return std::isfinite(orientation[0]) && std::isfinite(orientation[1]) && std::isfinite(orientation[2]) &&
         std::isfinite(orientation[3]);
}

} // namespace quiver::rt
