#pragma once
// The Cholesky factorisations of a group of small symmetric positive definite matrices at once,
// SIMD across the group: the Newton matrices of instances stepped together (step_many.h). Alone,
// an r = 30 factorisation runs along rows of 30 or fewer; across a group every operation is a full
// vector of lanes.
#include "reduced_polynomial.h"

namespace quiver::rt {

constexpr int kCholeskyLanes = ReducedPolynomial::kLanes;

// Where entry (i, j), i <= j, of an n x n upper triangle packed row by row sits (times the lane count in
// an interleaved array): the pair index of the reduced polynomial's K (reduced_polynomial.h).
inline size_t packedUpperIndex(int n, int i, int j) {
  return static_cast<size_t>(i) * n - static_cast<size_t>(i) * (i - 1) / 2 + static_cast<size_t>(j - i);
}

// A: kCholeskyLanes matrices, their upper triangles packed row by row and interleaved by lane
// (entry (i, j) of matrix l at A[packedUpperIndex(n, i, j) * kCholeskyLanes + l]), factorised in
// place into U (A = U^T U) by the operations choleskyFactor() (dense_solve.h) performs, in the same
// order. ok[l]: whether matrix l was positive definite; a lane that was not holds no factor, and
// the others are not affected by it.
void choleskyFactorLanes(double* A, int n, bool* ok);

// Lane `lane` of choleskyFactorLanes()'s factors, as choleskySubstitute() (dense_solve.h) reads
// it; none while A is null.
struct LaneFactor {
  static constexpr int kStride = kCholeskyLanes;
  const double* A = nullptr;
  int n = 0, lane = 0;
  const double* row(int i) const { return A + (packedUpperIndex(n, i, i) - static_cast<size_t>(i)) * kStride + lane; }
};

} // namespace quiver::rt
