// ReducedPolynomial::evaluateLanes: evaluate() for a group of states that share the coefficients.
// Values are stored lane-interleaved, [item][lane], so every loop below runs over the lanes of one
// item with a broadcast coefficient: SIMD across states, and each coefficient read once per group.
#include "reduced_polynomial.h"

#include <cstring>

#include "formats/model/qvr.h"
#include "simd_dispatch.h"

namespace quiver::rt {

namespace {

constexpr int L = ReducedPolynomial::kLanes;

// y[s] += Q[p][s] x[p] for s > p and y[p] += Q[p][s] x[s], as packedSymmetricProduct() does for
// one state, here four rows of one 8-aligned group per sweep (they share their first column).
template <class C>
QV_HOT void packedSymmetricProductLanes(const C* Q, const size_t* rowStart, const size_t* rowOffset, size_t n,
                                        const double* x, double* y) {
  std::memset(y, 0, sizeof(double) * n * L);
  size_t p = 0;
  for (; p + 4 <= n; p += 4) {
    const size_t start = rowStart[p];
    const C* r0 = Q + rowOffset[p] - start;
    const C* r1 = Q + rowOffset[p + 1] - start;
    const C* r2 = Q + rowOffset[p + 2] - start;
    const C* r3 = Q + rowOffset[p + 3] - start;
    double x0[L], x1[L], x2[L], x3[L], d0[L], d1[L], d2[L], d3[L];
    for (int l = 0; l < L; ++l) {
      x0[l] = x[p * L + l];
      x1[l] = x[(p + 1) * L + l];
      x2[l] = x[(p + 2) * L + l];
      x3[l] = x[(p + 3) * L + l];
      d0[l] = d1[l] = d2[l] = d3[l] = 0;
    }
    for (size_t s = start; s < n; ++s) {
      const double c0 = static_cast<double>(r0[s]), c1 = static_cast<double>(r1[s]);
      const double c2 = static_cast<double>(r2[s]), c3 = static_cast<double>(r3[s]);
      const double* xs = x + s * L;
      double* ys = y + s * L;
#pragma omp simd
      for (int l = 0; l < L; ++l) {
        d0[l] += c0 * xs[l];
        d1[l] += c1 * xs[l];
        d2[l] += c2 * xs[l];
        d3[l] += c3 * xs[l];
        ys[l] += c0 * x0[l] + c1 * x1[l] + c2 * x2[l] + c3 * x3[l];
      }
    }
    for (int l = 0; l < L; ++l) {
      y[p * L + l] += d0[l];
      y[(p + 1) * L + l] += d1[l];
      y[(p + 2) * L + l] += d2[l];
      y[(p + 3) * L + l] += d3[l];
    }
  }
  for (; p < n; ++p) {
    const C* row = Q + rowOffset[p] - rowStart[p];
    double xp[L], dot[L];
    for (int l = 0; l < L; ++l) {
      xp[l] = x[p * L + l];
      dot[l] = 0;
    }
    for (size_t s = rowStart[p]; s < n; ++s) {
      const double c = static_cast<double>(row[s]);
#pragma omp simd
      for (int l = 0; l < L; ++l) {
        dot[l] += c * x[s * L + l];
        y[s * L + l] += c * xp[l];
      }
    }
    for (int l = 0; l < L; ++l) y[p * L + l] += dot[l];
  }
}

// y[s] = sum_k q_k T_k[s] over the rows T_k of length n, four rows per sweep.
QV_HOT void sumOfRowsLanes(const double* T, int r, size_t n, const double* q, double* y) {
  std::memset(y, 0, sizeof(double) * n * L);
  int k = 0;
  for (; k + 4 <= r; k += 4) {
    const double *t0 = T + k * n, *t1 = t0 + n, *t2 = t1 + n, *t3 = t2 + n;
    const double *q0 = q + k * L, *q1 = q0 + L, *q2 = q1 + L, *q3 = q2 + L;
    for (size_t s = 0; s < n; ++s) {
      const double c0 = t0[s], c1 = t1[s], c2 = t2[s], c3 = t3[s];
#pragma omp simd
      for (int l = 0; l < L; ++l) y[s * L + l] += c0 * q0[l] + c1 * q1[l] + c2 * q2[l] + c3 * q3[l];
    }
  }
  for (; k < r; ++k) {
    const double* t = T + k * n;
    const double* qk = q + k * L;
    for (size_t s = 0; s < n; ++s) {
      const double c = t[s];
#pragma omp simd
      for (int l = 0; l < L; ++l) y[s * L + l] += c * qk[l];
    }
  }
}

} // namespace

size_t ReducedPolynomial::laneScratchSize(int r) {
  return (monomialCount2(r) * 3 + 2 * static_cast<size_t>(r) + 1) * L;
}

QV_HOT void ReducedPolynomial::evaluateLanes(const double* const* q, int count, double* energy, double* const* force,
                                             double* stiffness, double* scratch) const {
  const int r = r_;
  const size_t P = pairs_;
  double* x = scratch;   // [pair][lane]: w_kl q_k q_l
  double* y3 = x + P * L;
  double* y4 = y3 + P * L;
  double* ql = y4 + P * L;  // [k][lane]: q, zero in unused lanes
  double* Rq = ql + static_cast<size_t>(r) * L;
  double* e = Rq + static_cast<size_t>(r) * L;
  for (int k = 0; k < r; ++k)
    for (int l = 0; l < L; ++l) ql[k * L + l] = l < count ? q[l][k] : 0.0;
  for (int k = 0, s = 0; k < r; ++k)
    for (int m = k; m < r; ++m, ++s)
#pragma omp simd
      for (int l = 0; l < L; ++l) x[s * L + l] = (k == m ? 0.5 : 1.0) * ql[k * L + l] * ql[m * L + l];
  if (q32_)
    packedSymmetricProductLanes(q32_, rowStart_, rowOffset_, P, x, y4);
  else
    packedSymmetricProductLanes(q64_, rowStart_, rowOffset_, P, x, y4);
  sumOfRowsLanes(t_, r, P, ql, y3);
  std::memset(Rq, 0, sizeof(double) * r * L);
  std::memset(e, 0, sizeof(double) * L);
  // K, the force and the energy as evaluate() assembles them, pair by pair, SIMD across the states.
  for (int a = 0, p = 0; a < r; ++a)
    for (int b = a; b < r; ++b, ++p) {
      const double k2 = k2_[p], weight = a == b ? 1.0 : 2.0;
#pragma omp simd
      for (int l = 0; l < L; ++l) {
        const double s3 = y3[p * L + l], s4 = y4[p * L + l];
        stiffness[p * L + l] = k2 + s3 + s4;
        const double f = k2 + s3 / 2 + s4 / 3, h = k2 / 2 + s3 / 6 + s4 / 12;
        const double qa = ql[a * L + l], qb = ql[b * L + l];
        Rq[a * L + l] += f * qb;
        if (b != a) Rq[b * L + l] += f * qa;
        e[l] += weight * h * qa * qb;
      }
    }
  for (int l = 0; l < count; ++l) {
    for (int i = 0; i < r; ++i) force[l][i] = Rq[i * L + l];
    energy[l] = e[l];
  }
}

} // namespace quiver::rt
