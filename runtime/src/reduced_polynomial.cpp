#include "reduced_polynomial.h"

#include <cstdint>
#include <cstring>
#include <utility>

#include "formats/model/qvr.h"

#include "simd_dispatch.h"

namespace quiver::rt {

namespace {

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

// Q's upper triangle is stored in groups of eight rows (pairs p..p+7, p a multiple of 8), over the
// pairs padded to whole groups (n = blockedRows(P), zeros beyond P). The group's rows all start at
// column p and run to n, and are interleaved eight columns at a time, [column / 8][row][column % 8],
// so that a sweep over the group reads one sequential stream (eight streams, one per row, had cost
// 7-15% at r = 30 and 40 with the coefficients in L3) and has no tail.
constexpr size_t kGroup = ReducedPolynomial::kBlock;  // rows per group, and columns per interleaved run
static_assert(kGroup == 8, "groupOffset() sums 8 (n - g)");
// Where the group of pair p (a multiple of 8) begins: 8 (n - g) summed over the groups g < p before it.
size_t groupOffset(size_t n, size_t p) { return p * n + 4 * p - p * p / 2; }
size_t packedCount(size_t n) { return groupOffset(n, n); }
// Where row `row` of a group holds its column `column`, both counted from the group's first pair.
constexpr size_t inGroup(size_t row, size_t column) {
  return column / kGroup * kGroup * kGroup + row * kGroup + column % kGroup;
}
// Where entry (p, s), p <= s, of the upper triangle sits.
size_t packedAt(size_t n, size_t p, size_t s) {
  const size_t first = p / kGroup * kGroup;
  return groupOffset(n, first) + inGroup(p - first, s - first);
}

// W values of T in one vector (GCC's vector extension: each clone maps it onto its own registers).
template <class T, int W>
struct Vector {
  typedef T type __attribute__((vector_size(W * sizeof(T))));
};

// W coefficients from `at` as a vector of doubles: written lane by lane, which GCC turns into one
// vcvtps2pd from memory (its __builtin_convertvector converted two halves and reassembled them).
template <class Vd, class C, int... I>
[[gnu::always_inline]] inline void widen(const C* at, std::integer_sequence<int, I...>, Vd& v) {
  v = Vd{static_cast<double>(at[I])...};  // by reference: returned, a vector's ABI depends on the clone
}

// y[s] += Q[p][s] x[p] for s > p and y[p] += sum_s Q[p][s] x[s]: one pass over row p of the upper
// triangle does both halves of the symmetric product (the stored diagonal is halved). A group's
// eight rows are swept together, W columns at a time, so y is loaded and stored and x read once
// for all eight: per coefficient, one multiply-add into its row's dot product and one into y.
// Written with vectors of W doubles: W = 4 where 16 vector registers must hold the eight dot
// products, the eight x[p] and the converted coefficients; left to the vectoriser, float32
// coefficients made it sweep eight columns at a time and spill every dot product to the stack.
template <int W, class C>
QV_HOT void packedSymmetricProduct(const C* Q, size_t n, const double* x, double* y) {
  using Vd = typename Vector<double, W>::type;
  constexpr size_t G = kGroup;
  static_assert(G % W == 0, "a vector of columns stays within one interleaved run");
  for (size_t s = 0; s < n; ++s) y[s] = 0;
  for (size_t p = 0; p < n; p += G) {
    const size_t length = n - p;
    const C* group = Q + groupOffset(n, p);
    Vd dot[G], xp[G];
    for (size_t g = 0; g < G; ++g) {
      dot[g] = Vd{};
      xp[g] = Vd{} + x[p + g];
    }
    for (size_t s = 0; s < length; s += W) {
      Vd xs, ys, c, half[2];
      std::memcpy(&xs, x + p + s, sizeof xs);
      // Row by row, so that one converted coefficient vector is live at a time (all eight at once
      // left no register for the eighth dot product). Unrolled: left rolled by GCC in the AVX-512
      // clone, it carried dot, xp and half through the stack (the evaluation about 2x slower).
#pragma GCC unroll 8
      for (size_t g = 0; g < G; ++g) {
        widen(group + inGroup(g, s), std::make_integer_sequence<int, W>(), c);
        dot[g] += c * xs;
        half[g / 4] = g % 4 ? half[g / 4] + c * xp[g] : c * xp[g];
      }
      std::memcpy(&ys, y + p + s, sizeof ys);
      ys += half[0] + half[1];
      std::memcpy(y + p + s, &ys, sizeof ys);
    }
    for (size_t g = 0; g < G; ++g)
      for (int w = 0; w < W; ++w) y[p + g] += dot[g][w];
  }
}

// y[i] = sum_k B_ik q_k, k in order, for the N row blocks at B (ReducedPolynomial::kBlock rows
// each, `stride` doubles apart): N independent running sums, where one block alone would wait on
// the multiply-add latency at every k.
template <size_t N>
[[gnu::always_inline]] inline void blockedSweep(const double* B, size_t stride, int r, const double* q, double* y) {
  constexpr size_t G = ReducedPolynomial::kBlock;
  double sum[N][G] = {};
  for (int k = 0; k < r; ++k) {
    const double qk = q[k];
    for (size_t m = 0; m < N; ++m)
#pragma omp simd
      for (size_t g = 0; g < G; ++g) sum[m][g] += B[m * stride + k * G + g] * qk;
  }
  for (size_t m = 0; m < N; ++m)
#pragma omp simd
    for (size_t g = 0; g < G; ++g) y[m * G + g] = sum[m][g];
}

// The same over all the rows of a blocked matrix (y has room for the last block's padding rows), N
// blocks per sweep: eight (eight vectors of eight running sums) with AVX-512's 32 registers, four
// (eight vectors of four) with AVX2's 16. The number of blocks a sweep takes is fixed at compile
// time: a count known only at run time (the last sweep's) had GCC test it at every k (the whole
// evaluation 3% slower at r = 30). The sums run in the same order as before.
template <size_t N>
QV_HOT void blockedProduct(const double* B, int r, size_t rows, const double* q, double* y) {
  constexpr size_t G = ReducedPolynomial::kBlock;
  const size_t stride = static_cast<size_t>(r) * G, blocks = (rows + G - 1) / G;
  size_t b = 0;
  for (; b + N <= blocks; b += N) blockedSweep<N>(B + b * stride, stride, r, q, y + b * G);
  for (; b + 2 <= blocks; b += 2) blockedSweep<2>(B + b * stride, stride, r, q, y + b * G);
  if (b < blocks) blockedSweep<1>(B + b * stride, stride, r, q, y + b * G);
}

// The energy's monomials (ReducedPolynomial::monomials_) come in runs, each against a tail of the
// pair products x (pairs in row order, then kRun zeros): padded to whole runs of kRun doubles, a
// run is swept by four independent vectors of four with no tail loop (one vector alone would wait
// on the multiply-add latency).
constexpr size_t kRun = 16;
size_t wholeRuns(size_t length) { return (length + kRun - 1) / kRun * kRun; }
// The pairs (k, l), k <= l, from pair (j, j) to the last: the monomials that complete a run whose
// indices so far end with j.
size_t tailFrom(int r, int j) { return monomialCount2(r - j); }
size_t monomialsCount(int r) {
  size_t count = wholeRuns(monomialCount2(r));
  for (int i = 0; i < r; ++i) count += wholeRuns(tailFrom(r, i));
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j) count += wholeRuns(tailFrom(r, j));
  return count;
}

// sum += w sum_s c[s] x[s] over a run padded to whole kRun, as a vector summed once at the end (by
// reference: returned, a vector's ABI depends on the clone).
using V4 = Vector<double, 4>::type;
[[gnu::always_inline]] inline void addRun(const double* c, const double* x, size_t length, double w, V4& sum) {
  V4 s[4] = {};
  for (size_t i = 0; i < length; i += kRun)
    for (int v = 0; v < 4; ++v) {
      V4 cv, xv;
      std::memcpy(&cv, c + i + 4 * v, sizeof cv);
      std::memcpy(&xv, x + i + 4 * v, sizeof xv);
      s[v] += cv * xv;
    }
  sum += w * ((s[0] + s[1]) + (s[2] + s[3]));
}

// E(q) = sum c2 x + sum_i q_i (c3 run i . x tail) + sum_{i<=j} x_ij (c4 run ij . x tail), with
// x_kl = q_k q_l for the pairs in row order (P of them, kRun zeros after).
QV_HOT double monomialEnergy(const double* c, int r, const double* q, const double* x) {
  const size_t P = monomialCount2(r);
  V4 sum = {};
  addRun(c, x, P, 1.0, sum);
  c += wholeRuns(P);
  for (int i = 0; i < r; ++i) {
    const size_t length = tailFrom(r, i);
    addRun(c, x + (P - length), length, q[i], sum);
    c += wholeRuns(length);
  }
  for (int i = 0, p = 0; i < r; ++i)
    for (int j = i; j < r; ++j, ++p) {
      const size_t length = tailFrom(r, j);
      addRun(c, x + (P - length), length, x[p], sum);
      c += wholeRuns(length);
    }
  return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}

// K(q) (with K, row-major), R(q) into R and E(q) from the stiffness polynomial's parts per pair
// (k2, K_3 and K_4: the header's formulas), a row at a time: R_a's own terms as one sum, the other
// rows' as axpys into R (summed into R_a in memory, one term after another, they waited on a
// store at every pair), K's upper triangle stored as it comes and mirrored after.
template <bool withK>
QV_HOT double assemble(const double* __restrict k2, const double* __restrict y3, const double* __restrict y4, int r,
                       const double* __restrict q, double* __restrict K, double* __restrict R) {
  const auto stiffnessAt = [&](size_t p) { return k2[p] + y3[p] + y4[p]; };
  const auto forceWeight = [&](size_t p) { return ReducedPolynomial::forceWeight(k2[p], y3[p], y4[p]); };
  const auto energyWeight = [&](size_t p) { return ReducedPolynomial::energyWeight(k2[p], y3[p], y4[p]); };
  for (int i = 0; i < r; ++i) R[i] = 0;
  double e = 0;
  for (int a = 0; a < r; ++a) {
    const size_t p = monomialIndex2(r, a, a);
    const double qa = q[a];
    if (withK) K[a * r + a] = stiffnessAt(p);
    double dot = forceWeight(p) * qa, energy = 0;
#pragma omp simd reduction(+ : dot, energy)
    for (int b = a + 1; b < r; ++b) {
      const size_t pb = p + static_cast<size_t>(b - a);
      if (withK) K[a * r + b] = stiffnessAt(pb);
      const double f = forceWeight(pb);
      dot += f * q[b];
      R[b] += f * qa;
      energy += energyWeight(pb) * q[b];
    }
    R[a] += dot;
    e += qa * (2 * energy + energyWeight(p) * qa);
  }
  if (withK)
    for (int a = 1; a < r; ++a)
      for (int b = 0; b < a; ++b) K[a * r + b] = K[b * r + a];
  return e;
}

} // namespace

ReducedPolynomial::Arrays ReducedPolynomial::carve(BlockCarver& c, bool single, bool monomials, bool groups) const {
  Arrays a{};
  a.k2 = c.take<double>(pairs_);
  a.t = c.take<double>(static_cast<size_t>(r_) * blockedRows(pairs_));
  if (single)
    a.q32 = c.take<float>(packedCount(blockedRows(pairs_)));
  else
    a.q64 = c.take<double>(packedCount(blockedRows(pairs_)));
  if (monomials) a.monomials = c.take<double>(monomialsCount(r_));
  if (!groups) return a;
  const size_t d = static_cast<size_t>(r_) * blockedRows(triples_);
  if (single)
    a.d32 = c.take<float>(d);
  else
    a.d64 = c.take<double>(d);
  a.tripleOf = c.take<uint32_t>(static_cast<size_t>(r_) * blockedRows(pairs_));
  return a;
}

size_t ReducedPolynomial::measure(int r, bool single, bool monomials, bool groups) {
  ReducedPolynomial measured;
  measured.r_ = r;
  measured.pairs_ = monomialCount2(r);
  measured.triples_ = monomialCount3(r);
  BlockCarver c(nullptr);
  measured.carve(c, single, monomials, groups);
  return c.size();
}

size_t ReducedPolynomial::storageBytes(int r, bool single, bool groups) { return measure(r, single, true, groups); }

size_t ReducedPolynomial::evaluationBytes(int r, bool single) { return measure(r, single, false, false); }

size_t ReducedPolynomial::scratchSize(int r) {
  // evaluate()'s three arrays of blockedRows(P) >= 8 doubles, and r; the monomials' P pair products
  // and kRun zeros fit in them.
  return blockedRows(monomialCount2(r)) * 3 + static_cast<size_t>(r);
}

void ReducedPolynomial::build(int r, const double* c, bool single, bool groups, void* storage) {
  r_ = r;
  pairs_ = monomialCount2(r);
  triples_ = monomialCount3(r);
  const size_t P = pairs_;
  BlockCarver carver(static_cast<char*>(storage));
  const Arrays arrays = carve(carver, single, true, groups);
  std::memset(storage, 0, carver.size());
  double* k2 = arrays.k2;
  double* t = arrays.t;
  void* Q = single ? static_cast<void*>(arrays.q32) : static_cast<void*>(arrays.q64);
  const size_t padded = blockedRows(P);
  auto setQ = [&](size_t p, size_t s, double value) {
    if (s < p) {
      const size_t x = p;
      p = s;
      s = x;
    }
    if (s == p) value *= 0.5;  // the product visits the diagonal twice
    const size_t at = packedAt(padded, p, s);
    if (single)
      static_cast<float*>(Q)[at] = static_cast<float>(value);
    else
      static_cast<double*>(Q)[at] = value;
  };

  const double* c2 = c;
  const double* c3 = c2 + monomialCount2(r);
  const double* c4 = c3 + monomialCount3(r);
  for (int a = 0; a < r; ++a)
    for (int b = a; b < r; ++b) k2[pairIndex(r, a, b)] = (a == b ? 2.0 : 1.0) * c2[monomialIndex2(r, a, b)];
  // Each monomial fixes the derivative tensor on every permutation of its indices: pick two of its
  // positions as the pair (a, b); the rest index the linear (k) or quadratic (k <= l) part.
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j)
      for (int k = j; k < r; ++k) {
        const int idx[3] = {i, j, k};
        const double T = c3[monomialIndex3(r, i, j, k)] * repeatFactor(idx);
        for (int x = 0; x < 3; ++x)
          for (int y = x + 1; y < 3; ++y) t[blockedAt(r, pairIndex(r, idx[x], idx[y]), idx[3 - x - y])] = T;
      }
  // The energy's monomials (monomials_), in the file's order: sorted tuples in lexicographic order,
  // so a run (padded to whole kRun) is the file's coefficients for its leading index or pair. The
  // quartic's as the stored layout rounds them: float32 holds the tensor entries, the coefficients
  // times repeatFactor().
  double* to = arrays.monomials;
  std::memcpy(to, c2, sizeof(double) * P);
  to += wholeRuns(P);
  for (int i = 0; i < r; ++i) {
    std::memcpy(to, c3 + monomialIndex3(r, i, i, i), sizeof(double) * tailFrom(r, i));
    to += wholeRuns(tailFrom(r, i));
  }
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; to += wholeRuns(tailFrom(r, j)), ++j)  // one run per leading pair
      for (int k = j, run = 0; k < r; ++k)
        for (int l = k; l < r; ++l, ++run) {
          const int idx[4] = {i, j, k, l};
          const double coefficient = c4[monomialIndex4(r, i, j, k, l)], factor = repeatFactor(idx);
          const double value = coefficient * factor;
          to[run] = single ? static_cast<double>(static_cast<float>(value)) / factor : coefficient;
          for (int x = 0; x < 4; ++x)
            for (int y = x + 1; y < 4; ++y) {
              int rest[2], n = 0;
              for (int s = 0; s < 4; ++s)
                if (s != x && s != y) rest[n++] = idx[s];
              setQ(pairIndex(r, idx[x], idx[y]), pairIndex(r, rest[0], rest[1]), value);
            }
          // Row (the triple left) and column (the index taken out) of the groups' two-pass rows.
          for (int x = 0; groups && x < 4; ++x) {
            int rest[3], n = 0;
            for (int s = 0; s < 4; ++s)
              if (s != x) rest[n++] = idx[s];
            const size_t at = blockedAt(r, monomialIndex3(r, rest[0], rest[1], rest[2]), idx[x]);
            if (single)
              arrays.d32[at] = static_cast<float>(value / 2);
            else
              arrays.d64[at] = value / 2;
          }
        }
  for (int a = 0, p = 0; groups && a < r; ++a)
    for (int b = a; b < r; ++b, ++p)
      for (int k = 0; k < r; ++k) {
        const int lo = k < a ? k : a, mid = k < a ? a : (k < b ? k : b), hi = k < b ? b : k;
        arrays.tripleOf[blockedAt(r, p, k)] = static_cast<uint32_t>(monomialIndex3(r, lo, mid, hi));
      }
  k2_ = arrays.k2;
  t_ = arrays.t;
  d64_ = arrays.d64;
  d32_ = arrays.d32;
  tripleOf_ = arrays.tripleOf;
  monomials_ = arrays.monomials;
  q64_ = arrays.q64;
  q32_ = arrays.q32;
}

void ReducedPolynomial::evaluate(const double* q, double* energy, double* force, double* stiffness,
                                 double* scratch) const {
  if (!force && !stiffness) {
    if (energy) *energy = energyFromMonomials(q, scratch);
    return;
  }
  const int r = r_;
  const size_t P = pairs_;
  const size_t n = blockedRows(P);
  double* x = scratch;  // w_kl q_k q_l, then zeros to n
  double* y3 = x + n;   // K_3(q) per pair
  double* y4 = y3 + n;  // K_4(q) per pair
  double* Rq = y4 + n;  // r
  size_t s = 0;
  for (int k = 0; k < r; ++k)
    for (int l = k; l < r; ++l) x[s++] = (k == l ? 0.5 : 1.0) * q[k] * q[l];
  for (; s < n; ++s) x[s] = 0;
  const bool wide = vectorRegisters32();
  if (q32_)
    wide ? packedSymmetricProduct<8>(q32_, n, x, y4) : packedSymmetricProduct<4>(q32_, n, x, y4);
  else
    wide ? packedSymmetricProduct<8>(q64_, n, x, y4) : packedSymmetricProduct<4>(q64_, n, x, y4);
  wide ? blockedProduct<8>(t_, r, P, q, y3) : blockedProduct<4>(t_, r, P, q, y3);
  const double e = stiffness ? assemble<true>(k2_, y3, y4, r, q, stiffness, Rq)
                             : assemble<false>(k2_, y3, y4, r, q, nullptr, Rq);
  if (force)
    for (int i = 0; i < r; ++i) force[i] = Rq[i];
  if (energy) *energy = e;
}

double ReducedPolynomial::energyFromMonomials(const double* q, double* scratch) const {
  const int r = r_;
  double* x = scratch;  // q_k q_l, pairs in row order, then kRun zeros for the runs' padding
  size_t s = 0;
  for (int k = 0; k < r; ++k)
    for (int l = k; l < r; ++l) x[s++] = q[k] * q[l];
  for (size_t z = 0; z < kRun; ++z) x[s++] = 0;
  return monomialEnergy(monomials_, r, q, x);
}

} // namespace quiver::rt
