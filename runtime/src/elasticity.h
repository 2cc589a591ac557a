#pragma once
// The elastic force model an instance steps with (qv_elasticity): the baked St.Venant-Kirchhoff
// polynomial, or linear modal dynamics with K(0), whose displacements modal warping then rotates.
#include "model.h"

namespace quiver::rt {

struct ElasticityEntry {
  qv_elasticity id;
  const char* name;
  const char* description;
  bool needsRotations;  // the model must carry MODAL_ROTATIONS
};
// Indexed by qv_elasticity: the one table of names.
extern const ElasticityEntry kElasticities[QV_ELASTICITY_COUNT];

// Elastic energy E(q), force R(q) and stiffness K(q) (any may be null). `scratch`:
// ReducedPolynomial::scratchSize(r) doubles.
void evaluateElasticity(const qv_model& model, qv_elasticity elasticity, const double* q, double* energy,
                        double* force, double* stiffness, double* scratch);

// E(q): the polynomial, or q^T K(0) q / 2.
double elasticEnergy(const qv_model& model, qv_elasticity elasticity, const double* q, double* scratch);

} // namespace quiver::rt
