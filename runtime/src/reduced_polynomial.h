#pragma once
// The reduced internal force and stiffness of a baked model, laid out for one streaming pass.
//
// The .qvr file stores the energy E(q) = E_2 + E_3 + E_4 (homogeneous parts of degree 2, 3, 4) as
// unique monomial coefficients. At load time they become the stiffness polynomial
//   K_ab(q) = k2_ab + sum_k T_abk q_k + sum_{k<=l} Q_ab,kl w_kl q_k q_l       (pairs a <= b)
// whose three parts are the Hessians of E_2, E_3 and E_4 (w_kl = 1/2 on the diagonal, 1 off it).
// Q, indexed by pairs on both sides, is symmetric, so only its upper triangle is stored, in groups
// of eight rows, and one pass over it does both halves of the product (a packed symmetric
// matrix-vector product). At r = 30 that is 113k coefficients: 0.91 MB in float64, 0.45 MB in
// float32 (a Zen 3's 512 KiB L2 holds neither with the rest: it streams them from L3). Euler's
// theorem for homogeneous functions then gives the force and the energy from the same parts, with
// no second pass:
//   R(q) = (K_2 + K_3(q)/2 + K_4(q)/3) q,   E(q) = q^T (K_2/2 + K_3(q)/6 + K_4(q)/12) q.
//
// Asked for the energy alone (the energy budgets' checks and draw-backs), evaluate() sums the
// monomials themselves, each degree's coefficients for a fixed leading index (or pair) against the
// contiguous tail of the pair products q_k q_l that completes them: 50k multiply-adds at r = 30
// from 0.40 MB (runs padded to 16), against the packed product's 230k from 0.91 MB (a copy of the file's coefficients,
// as the stored layout rounds them, so that it matches the full evaluation's energy to rounding).
//
// Groups of states (evaluateLanes), where the arithmetic, not the memory, bounds the work, contract
// the quartic part in two passes instead, with about a quarter fewer multiply-adds (177k instead of
// 230k at r = 30, the cubic part included): first U_ijk = sum_l D_ijkl q_l / 2 for the triples
// i <= j <= k (D the fourth derivative of E_4), then K_4,ab = sum_k U_sort(a,b,k) q_k. The rows
// of D are a layout of their own (1.2 MB more at r = 30 in float64), built only when asked.
#include <cstddef>
#include <cstdint>

#include "block_carver.h"

namespace quiver::rt {

class ReducedPolynomial {
public:
  // Bytes of storage for a basis of size r with coefficients in float32 (single) or float64, with
  // or without the groups' layout (evaluateLanes), and doubles of scratch for evaluate().
  static size_t storageBytes(int r, bool single, bool groups);
  static size_t scratchSize(int r);
  // The bytes of that storage one state's evaluate() reads (none of the groups' own arrays).
  static size_t evaluationBytes(int r, bool single);

  // Builds the layout in `storage` (storageBytes(r, single, groups) bytes, 64-byte aligned, owned
  // by the caller) from the energy monomial coefficients of formats/model/qvr.h.
  void build(int r, const double* energyCoefficients, bool single, bool groups, void* storage);

  // Any of energy, force (r) and stiffness (r x r, row-major) may be null; with both force and
  // stiffness null, the energy comes from the monomials (above). `scratch`: scratchSize(r) doubles.
  void evaluate(const double* q, double* energy, double* force, double* stiffness, double* scratch) const;

  // Rows of r coefficients, blocked eight rows at a time ([block][k][8]) so that one row block
  // times q is one vector of eight sums per k.
  static constexpr int kBlock = 8;
  // Rows padded to whole blocks, and where entry (i, k) of a blocked matrix of r columns sits.
  static size_t blockedRows(size_t rows) { return (rows + kBlock - 1) / kBlock * kBlock; }
  static size_t blockedAt(int r, size_t i, int k) {
    return (i / kBlock * r + static_cast<size_t>(k)) * kBlock + i % kBlock;
  }

  // The same for up to kLanes states at once (reduced_polynomial_lanes.cpp), with the groups'
  // layout only (groups()): each coefficient is read once for all of them and multiplies a vector
  // of kLanes values, one per state: the work is bound by arithmetic, not by streaming the
  // coefficients from L2 as one state's is. Entry i of q, energy and force belongs to state
  // i < count (none may be null); `stiffness` receives the K(q) of all kLanes lanes (unused lanes:
  // at q = 0), upper triangles packed row by row and interleaved by lane: K_ab of state l at
  // stiffness[p * kLanes + l], p the pair (a <= b) in row order (r(r+1)/2 x kLanes doubles). The
  // sums run in another order than evaluate()'s, so results agree with it to rounding, not bit for
  // bit. `scratch`: laneScratchSize(r) doubles, 64-byte aligned.
  // Sixteen: each broadcast coefficient multiplies two AVX-512 vectors of states (or four AVX2
  // ones), so the loads and the L3 stream per state are half of eight lanes' (the first pass at
  // r = 30 ran at 71 GFLOP/s with eight lanes, 94 with sixteen, of a 110 GFLOP/s Zen 5 peak).
  static constexpr int kLanes = 16;
  static size_t laneScratchSize(int r);
  void evaluateLanes(const double* const* q, int count, double* energy, double* const* force, double* stiffness,
                     double* scratch) const;

  // Euler's weights for one pair from its parts k2, K_3 and K_4 (the header's formulas): R(q) sums
  // forceWeight q_b per row, E(q) is q^T energyWeight q. evaluate() and evaluateLanes() both use them.
  static double forceWeight(double k2, double k3, double k4) { return k2 + 0.5 * k3 + kThird * k4; }
  static double energyWeight(double k2, double k3, double k4) { return 0.5 * k2 + kSixth * k3 + kTwelfth * k4; }

  int r() const { return r_; }
  bool single() const { return q32_ != nullptr; }
  bool groups() const { return tripleOf_ != nullptr; }

private:
  struct Arrays {
    double* k2;
    double* t;
    double* q64;
    float* q32;
    double* d64;
    float* d32;
    uint32_t* tripleOf;
    double* monomials;
  };
  // Takes the arrays for r_ from `c` (null pointers while it measures): one state's, then, with
  // `monomials`, the energy's own, and with `groups`, the groups' own.
  Arrays carve(BlockCarver& c, bool single, bool monomials, bool groups) const;
  static size_t measure(int r, bool single, bool monomials, bool groups);
  // The energy summed monomial by monomial (evaluate() asked for it alone).
  double energyFromMonomials(const double* q, double* scratch) const;

  // Euler's weights (the header's formulas) as products: three divisions per pair had cost about
  // a tenth of an evaluation.
  static constexpr double kThird = 1.0 / 3, kSixth = 1.0 / 6, kTwelfth = 1.0 / 12;

  int r_ = 0;
  size_t pairs_ = 0;             // P = r(r+1)/2, for (a <= b) and for the products z_kl = q_k q_l
  const double* k2_ = nullptr;   // [pair]
  size_t triples_ = 0;           // C(r+2, 3), for i <= j <= k
  const double* t_ = nullptr;    // T_abk, rows (a <= b) blocked over k: K_3 = t_ q
  const double* q64_ = nullptr;  // Q's upper triangle (diagonal halved; groups of eight rows), float64, or null
  const float* q32_ = nullptr;   // the same in float32, or null
  const double* d64_ = nullptr;  // D_ijkl / 2, rows (i <= j <= k) blocked over l, float64, or null
  const float* d32_ = nullptr;   // the same in float32, or null
  const uint32_t* tripleOf_ = nullptr;  // the triple sort(a, b, k), blocked over k as t_ is
  // The energy's coefficients by degree, in runs of a fixed leading index (degree 3) or pair
  // (degree 4), each padded with zeros to whole kRun doubles (reduced_polynomial.cpp).
  const double* monomials_ = nullptr;
};

} // namespace quiver::rt
