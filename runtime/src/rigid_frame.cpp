#include "rigid_frame.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "simd_dispatch.h"
#include "vec3.h"

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

// x = S^-1 b for a symmetric positive definite 3 x 3 S, by its adjugate.
void solve3(const double S[9], const double b[3], double x[3]) {
  const double c00 = S[4] * S[8] - S[5] * S[7], c01 = S[5] * S[6] - S[3] * S[8], c02 = S[3] * S[7] - S[4] * S[6];
  const double c11 = S[0] * S[8] - S[2] * S[6], c12 = S[2] * S[3] - S[0] * S[5], c22 = S[0] * S[4] - S[1] * S[3];
  const double det = S[0] * c00 + S[1] * c01 + S[2] * c02;
  x[0] = (c00 * b[0] + c01 * b[1] + c02 * b[2]) / det;
  x[1] = (c01 * b[0] + c11 * b[1] + c12 * b[2]) / det;
  x[2] = (c02 * b[0] + c12 * b[1] + c22 * b[2]) / det;
}

// The inertia of second moments S = \int rho p p^T: tr(S) 1 - S, symmetrised.
void inertiaOf(const double S[9], double I[9]) {
  const double trace = S[0] + S[4] + S[8];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) I[3 * a + b] = (a == b ? trace : 0.0) - 0.5 * (S[3 * a + b] + S[3 * b + a]);
}

// S^-1 (row-major, symmetric) of a symmetric positive definite 3 x 3 S, column by column.
void inverse3(const double S[9], double out[9]) {
  for (int c = 0; c < 3; ++c) {
    const double e[3] = {c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0};
    double column[3];
    solve3(S, e, column);
    for (int a = 0; a < 3; ++a) out[3 * a + c] = column[a];
  }
}

// x = A^-1 b for a general 3 x 3 A (row-major), by Cramer's rule; false where A is singular.
bool solveGeneral3(const double A[9], const double b[3], double x[3]) {
  const double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) + A[2] * (A[3] * A[7] - A[4] * A[6]);
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) return false;
  x[0] = (b[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (b[1] * A[8] - A[5] * b[2]) + A[2] * (b[1] * A[7] - A[4] * b[2])) / det;
  x[1] = (A[0] * (b[1] * A[8] - A[5] * b[2]) - b[0] * (A[3] * A[8] - A[5] * A[6]) + A[2] * (A[3] * b[2] - b[1] * A[6])) / det;
  x[2] = (A[0] * (A[4] * b[2] - b[1] * A[7]) - A[1] * (A[3] * b[2] - b[1] * A[6]) + b[0] * (A[3] * A[7] - A[4] * A[6])) / det;
  return true;
}

double dot(const double* a, const double* b, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

// Columns j0 .. j0 + width of the nine products M_ab^T x (below), summed over the rows k of M_ab in
// order: nine independent running sums of `width` (a full vector), where one alone would wait on
// the multiply-add latency at every k.
template <size_t W>
[[gnu::always_inline]] inline void transposedSweep(const double* M, const double* x, size_t n, size_t j0, size_t width,
                                                   double (&sum)[9][W]) {
  for (size_t k = 0; k < n; ++k) {
    const double xk = x[k];
    for (size_t ab = 0; ab < 9; ++ab) {
      const double* row = M + (ab * n + k) * n + j0;
      if (width == W) {
#pragma omp simd
        for (size_t l = 0; l < W; ++l) sum[ab][l] += row[l] * xk;
      } else {
        for (size_t l = 0; l < width; ++l) sum[ab][l] += row[l] * xk;
      }
    }
  }
}

// out_ab = base_ab + M_ab^T x for the nine r x r row-major blocks M_ab (ab = 3a + b), base_ab of r
// each (null: none), by the rows of M_ab, which are contiguous (a dot product per row would not
// vectorise: its sum is ordered). W columns at a time: eight with AVX-512's 32 registers, four
// with AVX2's 16 (nine vectors of running sums either way).
template <size_t W>
QV_HOT void transposedProducts(const double* base, const double* M, const double* x, int r, double* out) {
  const size_t n = static_cast<size_t>(r);
  for (size_t j0 = 0; j0 < n; j0 += W) {
    const size_t width = std::min(W, n - j0);
    double sum[9][W] = {};
    if (width == W) {
      transposedSweep<W>(M, x, n, j0, W, sum);
    } else {
      transposedSweep<W>(M, x, n, j0, width, sum);
    }
    for (size_t ab = 0; ab < 9; ++ab)
      for (size_t l = 0; l < width; ++l) out[ab * n + j0 + l] = (base ? base[ab * n + j0 + l] : 0.0) + sum[ab][l];
  }
}

void transposedProducts(const double* base, const double* M, const double* x, int r, double* out) {
  vectorRegisters32() ? transposedProducts<8>(base, M, x, r, out) : transposedProducts<4>(base, M, x, r, out);
}

// M += G^T Z for 3 x r row-major G and Z and an r x r row-major M: row j gains sum_a G_aj Z_a.
QV_HOT void addRank3(const double* G, const double* Z, int r, double* M) {
  const size_t n = static_cast<size_t>(r);
  for (size_t j = 0; j < n; ++j) {
    const double g0 = G[j], g1 = G[n + j], g2 = G[2 * n + j];
    double* row = M + j * n;
    for (size_t k = 0; k < n; ++k) row[k] += g0 * Z[k] + g1 * Z[n + k] + g2 * Z[2 * n + k];
  }
}

// out_i -= sum_ab W_ab X_ab[i] for nine blocks X_ab of n entries, `stride` apart: one pass over out.
QV_HOT void subtractWeighted(const double W[9], const double* X, size_t stride, size_t n, double* out) {
  for (size_t i = 0; i < n; ++i) {
    double sum = 0;
    for (int ab = 0; ab < 9; ++ab) sum += W[ab] * X[ab * stride + i];
    out[i] -= sum;
  }
}

} // namespace

void RigidFrame::attach(double* scratch, int r) {
  moments = scratch;
  products = scratch ? scratch + 9 * static_cast<size_t>(r) : nullptr;
}

void RigidFrame::setOrientation(const double qn[4]) {
  const double len = std::sqrt(qn[0] * qn[0] + qn[1] * qn[1] + qn[2] * qn[2] + qn[3] * qn[3]);
  const double unit[4] = {qn[0] / len, qn[1] / len, qn[2] / len, qn[3] / len};
  takeOrientation(unit);
}

void RigidFrame::takeOrientation(const double unit[4]) {
  const double w = unit[0], x = unit[1], y = unit[2], z = unit[3];
  orientation[0] = w, orientation[1] = x, orientation[2] = y, orientation[3] = z;
  const double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                       2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                       2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
  std::memcpy(rotation, R, sizeof R);
}

void RigidFrame::refresh(const qv_model& model, const double* q, const double* qdot) {
  const int r = model.info.r;
  const Moments mo(model);
  // y_ab = B_ab + A_ba q = B_ab + A_ab^T q, A_ab = \int rho U_a U_b^T.
  transposedProducts(mo.B, mo.A, q, r, moments);
  // S_ab = S0_ab + B_ba q + y_ab q; I = tr(S) 1 - S; h_c = e_cab y_ab q'.
  double S[9];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      S[3 * a + b] = mo.S0[3 * a + b] + dot(mo.B + (3 * b + a) * static_cast<size_t>(r), q, r) +
                     dot(moments + (3 * a + b) * static_cast<size_t>(r), q, r);
  inertiaOf(S, inertia);
  for (int c = 0; c < 3; ++c) {
    internal[c] = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (a != b && a != c && b != c) internal[c] += epsilon(c, a, b) * dot(moments + (3 * a + b) * static_cast<size_t>(r), qdot, r);
  }
  double bodyL[3];
  multiplyTransposed3(rotation, angularMomentum, bodyL);
  for (int c = 0; c < 3; ++c) bodyL[c] -= internal[c];
  solve3(inertia, bodyL, bodyOmega);
}

double RigidFrame::spinRate(const qv_model& model) const {
  double bodyL[3], w[3], rest[3], I0[9];
  multiplyTransposed3(rotation, angularMomentum, bodyL);
  for (int c = 0; c < 3; ++c) bodyL[c] -= internal[c];
  solve3(inertia, bodyL, w);
  inertiaOf(Moments(model).S0, I0);
  solve3(I0, bodyL, rest);
  return std::sqrt(std::fmax(dot(w, w, 3), dot(rest, rest, 3)));
}

void RigidFrame::worldOmega(double omega[3]) const { multiply3(rotation, bodyOmega, omega); }

void RigidFrame::setWorldOmega(const double omega[3]) {
  multiplyTransposed3(rotation, omega, bodyOmega);
  double bodyL[3];
  for (int a = 0; a < 3; ++a) bodyL[a] = dot(inertia + 3 * a, bodyOmega, 3) + internal[a];
  multiply3(rotation, bodyL, angularMomentum);
  turnCredit = 0;
}

void RigidFrame::holdSpin() {
  multiplyTransposed3(rotation, angularMomentum, heldMomentum);
  for (int c = 0; c < 3; ++c) heldMomentum[c] -= internal[c];
  std::memcpy(heldAngularMomentum, angularMomentum, sizeof heldAngularMomentum);
}

double RigidFrame::turnExcess(const qv_model& model, const double* q, const double* qdot) {
  refresh(model, q, qdot);
  double next[3], w[3], v[3];
  multiplyTransposed3(rotation, angularMomentum, next);
  for (int c = 0; c < 3; ++c) next[c] -= internal[c];
  solve3(inertia, next, w);
  solve3(inertia, heldMomentum, v);
  const double after = 0.5 * dot(next, w, 3), before = 0.5 * dot(heldMomentum, v, 3);
  // Within rounding, none: it would only amplify the rounding of q' where q' is small.
  return std::fabs(after - before) > 1e-12 * (after + before) ? after - before : 0.0;
}

double RigidFrame::addCentrifugal(const qv_model& model, const double* q, double* resisting, double* jacobian) const {
  const int r = model.info.r;
  const size_t rr = static_cast<size_t>(r) * r;
  const Moments mo(model);
  // S(q) = S0 + (B_ab + B_ba) q + q^T A_ab q; q^T A_ab q = q^T A_ba q, and A_ba q = A_ab^T q is kept
  // (in products[ab]) for the gradient.
  transposedProducts(nullptr, mo.A, q, r, products);
  double S[9];
  for (int ab = 0; ab < 9; ++ab) {
    const int a = ab / 3, b = ab % 3;
    S[ab] = mo.S0[ab] + dot(mo.B + ab * static_cast<size_t>(r), q, r) + dot(mo.B + (3 * b + a) * static_cast<size_t>(r), q, r) +
            dot(q, products + ab * static_cast<size_t>(r), r);
  }
  double I[9], w[3];
  inertiaOf(S, I);
  solve3(I, heldMomentum, w);
  // dV/dq_j = -omega . I_j omega / 2 = -sum_ab W_ab (B_ab + A_ab q)_j, I_j = dI/dq_j and
  // W_ab = |omega|^2 d_ab - omega_a omega_b (A_ab q = products[ba], W symmetric).
  const double w2 = dot(w, w, 3);
  double W[9];
  for (int ab = 0; ab < 9; ++ab) W[ab] = (ab % 4 == 0 ? w2 : 0.0) - w[ab / 3] * w[ab % 3];
  subtractWeighted(W, mo.B, r, r, resisting);
  subtractWeighted(W, products, r, r, resisting);
  // Its Hessian, with omega = I^-1 L_b moving with q (d omega/dq_k = -I^-1 I_k omega):
  //   -sum_ab W_ab A_ab  +  g_j . I^-1 g_k,  g_j = I_j omega = tr(S_j) omega - S_j omega, S_j = dS/dq_j;
  // the first softens, the second (rank 3, positive semidefinite) stiffens. Without the second
  // (omega held) the minimiser stopped at its eighth iteration at nearly every step of a bar spun
  // at 100 rad/s, 5.4 a step with it. Both symmetric to rounding (the factorisations read the upper
  // triangle).
  subtractWeighted(W, mo.A, rr, rr, jacobian);
  double inverse[9];
  inverse3(I, inverse);
  double* g = products + 9 * static_cast<size_t>(r);  // 3 x r: g_j by component
  double* z = g + 3 * static_cast<size_t>(r);          // 3 x r: I^-1 g_j
  for (int j = 0; j < r; ++j) {
    double Sj[9], gj[3];
    for (int ab = 0; ab < 9; ++ab) {
      const int ba = 3 * (ab % 3) + ab / 3;
      Sj[ab] = mo.B[ab * static_cast<size_t>(r) + j] + mo.B[ba * static_cast<size_t>(r) + j] +
               products[ab * static_cast<size_t>(r) + j] + products[ba * static_cast<size_t>(r) + j];
    }
    const double traceJ = Sj[0] + Sj[4] + Sj[8];
    for (int a = 0; a < 3; ++a) gj[a] = traceJ * w[a] - dot(Sj + 3 * a, w, 3);
    for (int a = 0; a < 3; ++a) {
      g[a * static_cast<size_t>(r) + j] = gj[a];
      z[a * static_cast<size_t>(r) + j] = dot(inverse + 3 * a, gj, 3);
    }
  }
  addRank3(g, z, r, jacobian);
  return 0.5 * dot(heldMomentum, w, 3);
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
  // The turn keeps the body-frame angular momentum's length and the rotational energy
  // (P - h_q).I^-1 (P - h_q) / 2, P = R^T L, exactly (I(q) and h_q of the step's start), at any spin:
  // the implicit midpoint rule on dP/dt = P x omega, P' - P = dt m x omega(m), m = (P + P') / 2,
  // solved by Newton (P' is P turned by the Cayley map of dt omega(m)), and R turned by that same
  // rotation, in substeps of at most half a radian (where Newton converges in a few iterations).
  // The midpoint orientation found by fixed-point iterations instead diverged past about 0.8 rad a
  // step: a bar spun at 100 rad/s in 1/60 s steps had its momentum thrown toward its long axis, and
  // its energy grew 560-fold in 20 s (FreeFlight.FastSpinsNeverGainEnergy).
  double inverse[9];  // I^-1
  inverse3(inertia, inverse);
  // (NaN: 1000, and the step resets.)
  const int substeps = std::max(1, static_cast<int>(std::fmin(std::ceil(h * std::sqrt(dot(bodyOmega, bodyOmega, 3)) / 0.5), 1000.0)));
  const double dt = h / substeps;
  for (int sub = 0; sub < substeps; ++sub) {
    double P[3], end[3], m[3], w[3];
    multiplyTransposed3(rotation, angularMomentum, P);
    std::memcpy(end, P, sizeof end);
    const auto midpoint = [&] {
      double b[3];
      for (int a = 0; a < 3; ++a) m[a] = 0.5 * (P[a] + end[a]), b[a] = m[a] - internal[a];
      for (int a = 0; a < 3; ++a) w[a] = dot(inverse + 3 * a, b, 3);
    };
    // A fixed count, so that the turn is a smooth function of the state (a group's instances and
    // the same ones stepped alone differ in rounding only).
    for (int it = 0; it < 6; ++it) {
      midpoint();
      double residual[3], c[3];
      cross3(m, w, c);
      for (int a = 0; a < 3; ++a) residual[a] = P[a] + dt * c[a] - end[a];
      // d(m x w)/d end = ([m]x I^-1 - [w]x) / 2.
      double J[9];
      for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k) {
          double mI = 0, wx = 0;
          for (int j = 0; j < 3; ++j) {
            wx += epsilon(a, j, k) * w[j];
            for (int l = 0; l < 3; ++l) mI += epsilon(a, j, l) * m[j] * inverse[3 * l + k];
          }
          J[3 * a + k] = (a == k ? 1.0 : 0.0) - 0.5 * dt * (mI - wx);
        }
      double step[3];
      if (!solveGeneral3(J, residual, step)) break;
      for (int a = 0; a < 3; ++a) end[a] += step[a];
    }
    midpoint();
    double omega[3];
    multiply3(rotation, w, omega);
    const double start[4] = {orientation[0], orientation[1], orientation[2], orientation[3]};
    turn(start, omega, dt);
  }
  for (int a = 0; a < 3; ++a) force[a] = torque[a] = 0;
}

void RigidFrame::turn(const double from[4], const double omega[3], double t) {
  // The Cayley map of t [omega]x: the quaternion (1, t omega / 2), normalised by setOrientation(),
  // times `from` (a turn by 2 atan(t |omega| / 2) about omega).
  const double q[4] = {1, 0.5 * t * omega[0], 0.5 * t * omega[1], 0.5 * t * omega[2]};
  const double* o = from;
  const double turned[4] = {q[0] * o[0] - q[1] * o[1] - q[2] * o[2] - q[3] * o[3],
                            q[0] * o[1] + q[1] * o[0] + q[2] * o[3] - q[3] * o[2],
                            q[0] * o[2] - q[1] * o[3] + q[2] * o[0] + q[3] * o[1],
                            q[0] * o[3] + q[1] * o[2] - q[2] * o[1] + q[3] * o[0]};
  setOrientation(turned);
}

void RigidFrame::toWorld(const double p[3], double out[3]) const {
  multiply3(rotation, p, out);
  for (int a = 0; a < 3; ++a) out[a] += position[a];
}

void RigidFrame::toBody(const double f[3], double out[3]) const { multiplyTransposed3(rotation, f, out); }

void RigidFrame::toWorldDirection(const double v[3], double out[3]) const { multiply3(rotation, v, out); }

void RigidFrame::inverseInertia(const double w[3], double out[3]) const {
  double body[3], x[3];
  multiplyTransposed3(rotation, w, body);
  solve3(inertia, body, x);
  multiply3(rotation, x, out);
}

void RigidFrame::inverseInertiaMatrix(double out[9]) const {
  double bodyInverse[9], turned[9];  // I^-1, then I^-1 R^T
  inverse3(inertia, bodyInverse);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) turned[3 * a + b] = dot(bodyInverse + 3 * a, rotation + 3 * b, 3);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      out[3 * a + b] = rotation[3 * a] * turned[b] + rotation[3 * a + 1] * turned[3 + b] + rotation[3 * a + 2] * turned[6 + b];
}

double RigidFrame::kineticEnergy(const qv_model& model) const {
  double spin = 0;
  for (int a = 0; a < 3; ++a) spin += bodyOmega[a] * (0.5 * dot(inertia + 3 * a, bodyOmega, 3) + internal[a]);
  return 0.5 * model.info.total_mass * dot(velocity, velocity, 3) + spin;
}

void RigidFrame::goHome() {
  std::memcpy(position, homePosition, sizeof position);
  setOrientation(homeOrientation);
  for (int a = 0; a < 3; ++a) velocity[a] = angularMomentum[a] = bodyOmega[a] = force[a] = torque[a] = 0;
  turnCredit = 0;
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
