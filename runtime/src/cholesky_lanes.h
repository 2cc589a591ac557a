#pragma once
// The Cholesky factorisations of a group of small symmetric positive definite matrices at once,
// SIMD across the group: the Newton matrices of instances stepped together (step_many.h). Alone,
// an r = 30 factorisation runs along rows of 30 or fewer; across a group every operation is a full
// vector of lanes.
#include <cstring>

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
  using Value = double;
  const double* A = nullptr;
  int n = 0, lane = 0;
  const double* row(int i) const { return A + (packedUpperIndex(n, i, i) - static_cast<size_t>(i)) * kStride + lane; }
  static void load(const double* at, double& value) { value = *at; }
};

// Four lanes of choleskyFactorLanes()'s factors at once (lanes 4 part to 4 part + 3), as
// choleskySubstitute() reads them: an entry is the vector of those lanes', and so is each
// right-hand side's entry (four lanes interleaved), so that the group's systems are solved four at
// a time, each lane by its own solve's operations. Four, not more: where vectors are four doubles
// wide, GCC moved eight-wide ones through the stack.
struct LanesFactor {
  static constexpr int kStride = kCholeskyLanes, kWidth = 4;
  typedef double Value __attribute__((vector_size(kWidth * sizeof(double))));
  const double* A;
  int n, part;
  const double* row(int i) const {
    return A + (packedUpperIndex(n, i, i) - static_cast<size_t>(i)) * kStride + kWidth * part;
  }
  // By reference: a returned vector's ABI depends on the instruction set it is compiled for.
  static void load(const double* at, Value& value) { std::memcpy(&value, at, sizeof value); }
};
static_assert(kCholeskyLanes % LanesFactor::kWidth == 0, "a group's lanes are whole LanesFactor parts");

} // namespace quiver::rt
