// ReducedPolynomial::evaluateLanes: evaluate() for a group of states that share the coefficients.
// Values are stored lane-interleaved, [item][lane], so every loop below runs over the lanes of one
// item with a broadcast coefficient: SIMD across states, and each coefficient read once per group.
#include "reduced_polynomial.h"

#include <cstring>
#include <type_traits>

#include "formats/model/qvr.h"
#include "simd_dispatch.h"

namespace quiver::rt {

namespace {

constexpr int L = ReducedPolynomial::kLanes;

// W doubles of one item's lanes as one vector (GCC's vector extension), loaded and stored through
// `At`. The kernels below hold their running sums in such vectors: kept in arrays of doubles, GCC
// spilled them at the end of every sweep and copied them out 16 bytes at a time, a quarter of the
// time of a sweep over r = 30.
template <int W>
struct Doubles {
  static_assert(L % W == 0, "an item's lanes are whole vectors");
  static constexpr int kPerItem = L / W;
  typedef double type __attribute__((vector_size(W * sizeof(double))));
  typedef double At __attribute__((vector_size(W * sizeof(double)), may_alias, aligned(sizeof(double))));
  // By reference: passed or returned by value, a vector's ABI depends on the clone.
  static const At& at(const double* p) { return *reinterpret_cast<const At*>(p); }
  static At& at(double* p) { return *reinterpret_cast<At*>(p); }
};

// Rows first..first+G-1 of one block of kBlock rows (`block`: [k][kBlock]) times q, lanes
// lane..lane+N*W-1: each coefficient broadcast against N vectors of q_k's lanes into G running
// sums of N vectors, kept in registers.
template <size_t G, int W, int N = Doubles<W>::kPerItem>
[[gnu::always_inline]] inline void blockRowsLanes(const double* block, size_t first, int lane, int r,
                                                  const double* q, double* y) {
  using V = Doubles<W>;
  constexpr size_t B = ReducedPolynomial::kBlock;
  q += lane, y += lane;
  typename V::type sum[G][N], qk[N];
  for (int n = 0; n < N; ++n) qk[n] = V::at(q + n * W);
  for (size_t g = 0; g < G; ++g)  // set at k = 0: zeroing it first costs a vector of zeros per sum
    for (int n = 0; n < N; ++n) sum[g][n] = block[first + g] * qk[n];
  for (int k = 1; k < r; ++k) {
    for (int n = 0; n < N; ++n) qk[n] = V::at(q + k * L + n * W);
    for (size_t g = 0; g < G; ++g)
      for (int n = 0; n < N; ++n) sum[g][n] += block[k * B + first + g] * qk[n];
  }
  for (size_t g = 0; g < G; ++g)
    for (int n = 0; n < N; ++n) V::at(y + (first + g) * L + n * W) = sum[g][n];
}

// y[i] = sum_k B_ik q_k for the rows of a blocked matrix (ReducedPolynomial::kBlock), k in order
// whatever the rows swept together: a whole block of all sixteen lanes per sweep with 32 vector
// registers (sixteen AVX-512 registers of sums), else four rows of eight lanes (eight AVX2
// registers; all sixteen lanes of two rows ran 25% slower, GCC reloading q_k for every row, and
// more sums spilled). y has room for the padding rows of the last block. float32 blocks are
// converted first into `block64` (r kBlock doubles): converted one by one in the loop, each would
// cost two more instructions per multiply-add.
template <class C>
QV_HOT void blockedProductLanes(const C* B, int r, size_t rows, const double* q, double* y, double* block64) {
  constexpr size_t G = ReducedPolynomial::kBlock;
  const bool wholeBlocks = vectorRegisters32();
  for (size_t i = 0; i < rows; i += G) {
    const double* block;
    if constexpr (std::is_same_v<C, double>) {
      block = B + i * r;
    } else {
#pragma omp simd
      for (size_t j = 0; j < r * G; ++j) block64[j] = static_cast<double>(B[i * r + j]);
      block = block64;
    }
    if (wholeBlocks) {
      blockRowsLanes<G, 8>(block, 0, 0, r, q, y + i * L);
    } else {
      for (int lane = 0; lane < L; lane += 8)
        for (size_t first = 0; first < G; first += G / 2) blockRowsLanes<G / 2, 4, 2>(block, first, lane, r, q, y + i * L);
    }
  }
}

// The second pass: y[p] = sum_k U[tripleOf[p][k]] q_k, G pairs per sweep (G running sums of L
// lanes), vectors of W doubles.
template <size_t G, int W>
[[gnu::always_inline]] inline void gatheredPairsLanes(const double* U, const uint32_t* tripleOf, int r, size_t p,
                                                      const double* q, double* y) {
  using V = Doubles<W>;
  constexpr int N = V::kPerItem;
  typename V::type sum[G][N];
  const auto triple = [&](size_t g, int k) {
    return U + static_cast<size_t>(tripleOf[ReducedPolynomial::blockedAt(r, p + g, k)]) * L;
  };
  typename V::type qk[N], u;
  for (int n = 0; n < N; ++n) qk[n] = V::at(q + n * W);
  for (size_t g = 0; g < G; ++g)
    for (int n = 0; n < N; ++n) u = V::at(triple(g, 0) + n * W), sum[g][n] = u * qk[n];
  for (int k = 1; k < r; ++k) {
    for (int n = 0; n < N; ++n) qk[n] = V::at(q + k * L + n * W);
    for (size_t g = 0; g < G; ++g)
      for (int n = 0; n < N; ++n) u = V::at(triple(g, k) + n * W), sum[g][n] += u * qk[n];
  }
  for (size_t g = 0; g < G; ++g)
    for (int n = 0; n < N; ++n) V::at(y + (p + g) * L + n * W) = sum[g][n];
}

// Running vectors as the first pass keeps them: eight pairs of two AVX-512 vectors, or two pairs of
// four AVX2 vectors (fewer would wait on the multiply-add latency).
template <int W>
QV_HOT void gatheredProductLanes(const double* U, const uint32_t* tripleOf, int r, size_t pairs, const double* q,
                                 double* y) {
  constexpr size_t G = (W == 8 ? 16 : 8) / Doubles<W>::kPerItem;
  size_t p = 0;
  for (; p + G <= pairs; p += G) gatheredPairsLanes<G, W>(U, tripleOf, r, p, q, y);
  for (; p < pairs; ++p) gatheredPairsLanes<1, W>(U, tripleOf, r, p, q, y);
}

} // namespace

size_t ReducedPolynomial::laneScratchSize(int r) {
  const size_t perLane =
      blockedRows(monomialCount3(r)) + blockedRows(monomialCount2(r)) + monomialCount2(r) + 2 * static_cast<size_t>(r) + 1;
  return perLane * L + static_cast<size_t>(r) * kBlock;  // and block64
}

QV_HOT void ReducedPolynomial::evaluateLanes(const double* const* q, int count, double* energy, double* const* force,
                                             double* stiffness, double* scratch) const {
  const int r = r_;
  const size_t P = pairs_;
  double* u = scratch;  // [triple][lane]: U_ijk (reduced_polynomial.h)
  double* y3 = u + blockedRows(triples_) * L;
  double* y4 = y3 + blockedRows(P) * L;
  double* ql = y4 + P * L;  // [k][lane]: q, zero in unused lanes
  double* Rq = ql + static_cast<size_t>(r) * L;
  double* e = Rq + static_cast<size_t>(r) * L;
  double* block64 = e + L;  // r kBlock doubles
  for (int k = 0; k < r; ++k)
    for (int l = 0; l < L; ++l) ql[k * L + l] = l < count ? q[l][k] : 0.0;
  if (d32_)
    blockedProductLanes(d32_, r, triples_, ql, u, block64);
  else
    blockedProductLanes(d64_, r, triples_, ql, u, block64);
  if (vectorRegisters32())
    gatheredProductLanes<8>(u, tripleOf_, r, P, ql, y4);
  else
    gatheredProductLanes<4>(u, tripleOf_, r, P, ql, y4);
  blockedProductLanes(t_, r, P, ql, y3, block64);
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
        const double f = forceWeight(k2, s3, s4), h = energyWeight(k2, s3, s4);
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
