#pragma once
// The equations of motion M q'' + C q' + R(q) + S(q) = f at a trial state, as the integrators use
// them (M = I: the basis is mass-orthonormal; C = alpha I + beta K(q), Rayleigh; S the state
// forces of loads.h, Jacobian J): forces, damping, and the Newton system
//   (I + c1 C + c2 (K + J)) x = rhs.
#include <cmath>

#include "instance.h"

namespace quiver::rt {

// E(q) (when `energy` is not null), R(q) into `force` and K(q) into s.work.stiffness: the
// group's preset when it was evaluated at exactly q (step_many.h; K left in the group's scratch,
// s.work.stiffnessPacked), else evaluated now. Returns whether K(q) is known to be positive definite
// (the group's presetDefinite).
bool elasticityAt(qv_instance& s, const double* q, double* energy, double* force);

// K(q) last evaluated, as a whole r x r matrix: s.work.stiffness, copied there first from the
// group's scratch if it is still there (s.work.stiffnessPacked).
const double* wholeStiffness(const qv_instance& s);

// D from K(x) into `D` (dampWithStiffness(); may be s.work.stiffness), as a minimising step that
// ended at x leaves it: K the last evaluation's when it was at x (`evaluatedAtX`), else K(x)
// evaluated now into s.work.stiffness (R(x) into s.work.force; a group's K pending is dropped).
void dampAt(const qv_instance& s, const double* x, bool evaluatedAtX, double* D, bool definite = false);

// Fills s.work.force = R(q) + S(q) and s.work.stiffness = K(q); returns J.
const double* evaluateForces(qv_instance& s, const double* q);

// C v = alpha v + beta K v into `out` (r values), K the elastic stiffness last evaluated (or, for
// the minimising solver, its damping stiffness D): K is symmetric, so the product runs along its
// rows as axpys (SIMD across i), each sum over j in order, instead of r chains of r dependent
// multiply-adds.
void dampingForces(const qv_instance& s, const double* K, const double* v, double* out);
// The same with K(q) last evaluated, read packed from the group's scratch while it is there.
void dampingForces(const qv_instance& s, const double* v, double* out);

// The fixed Newton step's (I + c1 C + c2 (K + J)), C = alpha I + beta K(q). Fused explicitly: the
// group and the solver compute it in code built for different instruction sets, and a group's
// factor is taken only when their scales agree bit for bit (takePresetFactor()).
inline SystemScales newtonSystem(const qv_instance& s, double c1, double c2) {
  return {std::fma(c1, s.config.rayleigh_beta, c2), c2, 0.0, std::fma(c1, s.config.rayleigh_alpha, 1.0)};
}

// D = K + mu I into `D` (may be K), K symmetric (r x r), mu the smallest of 0 and a ladder from
// 1e-6 of K's largest diagonal entry, each rung 4x the last (40 at most), that makes D positive
// definite (a negative damping would add energy). From K(0) where K is not finite (the step resets
// anyway); always positive definite, so that a snapshot of it restores. `definite`: K is known to be
// positive definite as choleskyFactor() judges (mu = 0, no factorisation).
void dampWithStiffness(const qv_instance& s, const double* K, double* D, bool definite = false);

// The matrix's upper triangle (all Cholesky reads) into s.work.system.
void fillSystem(qv_instance& s, const double* stateJacobian, const SystemScales& scales);

// The group's Cholesky factor (step_many.h) of the matrix with these scales at the point just
// evaluated, or none (A null); taken either way.
LaneFactor takePresetFactor(qv_instance& s, const SystemScales& scales);

// Solves the Newton system for the right-hand side in s.work.correction (the correction replaces
// it) by Cholesky; false when large compression has made the matrix indefinite (the step is then
// the minimiser's: fixed_newton.h, minimizedInstead()).
bool solveNewton(qv_instance& s, const double* stateJacobian, double c1, double c2);

} // namespace quiver::rt
