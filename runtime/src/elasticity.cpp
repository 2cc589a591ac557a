#include "elasticity.h"

#include <cstring>

namespace quiver::rt {

const ElasticityEntry kElasticities[QV_ELASTICITY_COUNT] = {
    {QV_ELASTICITY_STVK, "stvk", "St.Venant-Kirchhoff", false},
    {QV_ELASTICITY_LINEAR, "linear", "linear, K(0)", false},
    {QV_ELASTICITY_MODAL_WARPING, "warping", "modal warping", true},
};

void evaluateElasticity(const qv_model& m, qv_elasticity elasticity, const double* q, double* energy, double* force,
                        double* stiffness, double* scratch) {
  if (elasticity == QV_ELASTICITY_STVK) {
    m.polynomial.evaluate(q, energy, force, stiffness, scratch);
    return;
  }
  const int r = m.info.r;
  if (stiffness) std::memcpy(stiffness, m.restStiffness, sizeof(double) * r * r);
  if (force)
    for (int i = 0; i < r; ++i) {
      double s = 0;
      for (int j = 0; j < r; ++j) s += m.restStiffness[i * r + j] * q[j];
      force[i] = s;
    }
  if (energy) *energy = elasticEnergy(m, elasticity, q, scratch);
}

double elasticEnergy(const qv_model& m, qv_elasticity elasticity, const double* q, double* scratch) {
  double e = 0;
  if (elasticity == QV_ELASTICITY_STVK) {
    m.polynomial.evaluate(q, &e, nullptr, nullptr, scratch);
    return e;
  }
  const int r = m.info.r;
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < r; ++j) e += 0.5 * q[i] * m.restStiffness[i * r + j] * q[j];
  return e;
}

} // namespace quiver::rt
