#include "reduced_polynomial.h"

#include <algorithm>
#include <cstring>

#include "formats/model/qvr.h"

namespace quiver::rt {

namespace {

// Index of the sorted pair a <= b (lexicographic), the order shared by stiffness entries and z.
inline size_t pairIndex(int r, int a, int b) { return monomialIndex2(r, a, b); }

// Product of the factorials of how often each index repeats in a sorted tuple: the factor between
// a monomial's coefficient and the matching entry of the symmetric derivative tensor.
template <size_t N>
double repeatFactor(const int (&idx)[N]) {
  double f = 1;
  size_t run = 1;
  for (size_t s = 1; s <= N; ++s) {
    if (s < N && idx[s] == idx[s - 1]) {
      ++run;
    } else {
      for (size_t k = 2; k <= run; ++k) f *= static_cast<double>(k);
      run = 1;
    }
  }
  return f;
}

} // namespace

size_t ReducedPolynomial::storageSize(int r) {
  const size_t pairs = monomialCount2(r);
  return pairs * (1 + static_cast<size_t>(r) + pairs);
}

size_t ReducedPolynomial::scratchSize(int r) { return monomialCount2(r) * 4 + static_cast<size_t>(r); }

void ReducedPolynomial::build(int r, const double* c, double* storage) {
  r_ = r;
  pairs_ = monomialCount2(r);
  double* k2 = storage;
  double* k3 = k2 + pairs_;
  double* k4 = k3 + pairs_ * r;
  std::memset(storage, 0, storageSize(r) * sizeof(double));
  const double* c2 = c;
  const double* c3 = c2 + monomialCount2(r);
  const double* c4 = c3 + monomialCount3(r);
  for (int a = 0; a < r; ++a)
    for (int b = a; b < r; ++b) k2[pairIndex(r, a, b)] = (a == b ? 2.0 : 1.0) * c2[monomialIndex2(r, a, b)];
  // Each monomial fixes the derivative tensor on every permutation of its indices: pick two of its
  // positions as (a, b); the rest index the linear (k) or quadratic (k <= l) part of K_ab.
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j)
      for (int k = j; k < r; ++k) {
        const int idx[3] = {i, j, k};
        const double T = c3[monomialIndex3(r, i, j, k)] * repeatFactor(idx);
        for (int x = 0; x < 3; ++x)
          for (int y = x + 1; y < 3; ++y) k3[pairIndex(r, idx[x], idx[y]) * r + idx[3 - x - y]] = T;
      }
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j)
      for (int k = j; k < r; ++k)
        for (int l = k; l < r; ++l) {
          const int idx[4] = {i, j, k, l};
          const double Q = c4[monomialIndex4(r, i, j, k, l)] * repeatFactor(idx);
          for (int x = 0; x < 4; ++x)
            for (int y = x + 1; y < 4; ++y) {
              int rest[2], n = 0;
              for (int s = 0; s < 4; ++s)
                if (s != x && s != y) rest[n++] = idx[s];
              // (1/2) sum_{k,l} Q q_k q_l counts k != l twice and k == l once.
              k4[pairIndex(r, idx[x], idx[y]) * pairs_ + pairIndex(r, rest[0], rest[1])] = rest[0] == rest[1] ? 0.5 * Q : Q;
            }
        }
  k2_ = k2;
  k3_ = k3;
  k4_ = k4;
}

void ReducedPolynomial::evaluate(const double* q, double* energy, double* force, double* stiffness,
                                 double* scratch) const {
  const int r = r_;
  const size_t pairs = pairs_;
  double* z = scratch;                 // q_k q_l, k <= l
  double* K = z + pairs;               // stiffness, per pair
  double* F = K + pairs;               // K_2 + K_3/2 + K_4/3, per pair
  double* H = F + pairs;               // K_2/2 + K_3/6 + K_4/12, per pair
  double* Rq = H + pairs;              // r
  for (int k = 0, s = 0; k < r; ++k)
    for (int l = k; l < r; ++l) z[s++] = q[k] * q[l];
  for (size_t p = 0; p < pairs; ++p) {
    const double* row3 = k3_ + p * r;
    const double* row4 = k4_ + p * pairs;
    double s3 = 0, s4 = 0;
    for (int k = 0; k < r; ++k) s3 += row3[k] * q[k];
    for (size_t s = 0; s < pairs; ++s) s4 += row4[s] * z[s];
    K[p] = k2_[p] + s3 + s4;
    F[p] = k2_[p] + s3 / 2 + s4 / 3;
    H[p] = k2_[p] / 2 + s3 / 6 + s4 / 12;
  }
  std::fill(Rq, Rq + r, 0.0);
  double e = 0;
  for (int a = 0, p = 0; a < r; ++a)
    for (int b = a; b < r; ++b, ++p) {
      if (stiffness) stiffness[a * r + b] = stiffness[b * r + a] = K[p];
      Rq[a] += F[p] * q[b];
      if (b != a) Rq[b] += F[p] * q[a];
      e += (a == b ? 1.0 : 2.0) * H[p] * q[a] * q[b];
    }
  if (force) std::copy(Rq, Rq + r, force);
  if (energy) *energy = e;
}

} // namespace quiver::rt
