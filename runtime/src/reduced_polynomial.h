#pragma once
// The reduced internal force and stiffness of a baked model, laid out for one streaming pass.
//
// The .qvr file stores the energy E(q) = E_2 + E_3 + E_4 (homogeneous parts of degree 2, 3, 4) as
// unique monomial coefficients. At load time they are expanded, for every pair a <= b, into the
// stiffness polynomial K_ab(q) = k2_ab + sum_k k3_abk q_k + sum_{k<=l} k4_ab,kl q_k q_l, whose three
// parts are the Hessians of E_2, E_3 and E_4. Euler's theorem for homogeneous functions then gives
// the force and the energy from the same parts, with no second pass over the coefficients:
//   R(q) = (K_2 + K_3(q)/2 + K_4(q)/3) q,   E(q) = q^T (K_2/2 + K_3(q)/6 + K_4(q)/12) q.
#include <cstddef>

namespace quiver::rt {

class ReducedPolynomial {
public:
  // Doubles of storage for a basis of size r, and of scratch for evaluate().
  static size_t storageSize(int r);
  static size_t scratchSize(int r);

  // Builds the layout in `storage` (storageSize(r) doubles, owned by the caller) from the energy
  // monomial coefficients of formats/model/qvr.h.
  void build(int r, const double* energyCoefficients, double* storage);

  // Any of energy, force (r) and stiffness (r x r, row-major) may be null. `scratch`: scratchSize(r) doubles.
  void evaluate(const double* q, double* energy, double* force, double* stiffness, double* scratch) const;

  int r() const { return r_; }

private:
  int r_ = 0;
  size_t pairs_ = 0;         // r(r+1)/2, both for (a <= b) and for the products z_kl = q_k q_l
  const double* k2_ = nullptr;  // [pair]
  const double* k3_ = nullptr;  // [pair][k]
  const double* k4_ = nullptr;  // [pair][kl]
};

} // namespace quiver::rt
