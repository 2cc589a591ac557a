#pragma once
// Stage "export": the runtime model NAME.qvr (formats/model/QVR.md) from the bake's results:
// energy polynomial, basis rows, rest positions, surface triangles, the vertex map back to the
// mesh file, the gravity projection U^T M e_a, eigenvalues, material, default damping, and the
// modal rotations (1/2 curl of each basis vector at the vertices) for modal warping.
#include <vector>

#include <Eigen/Core>

#include "common/mesh_checks.h"
#include "formats/model/qvr_writer.h"
#include "precompute/stages/polynomials.h"

namespace quiver {

struct ExportSettings {
  int basisPrecision = 32;   // bits per stored basis entry: 32 (default, half the size) or 64
  double dampingRatio = 0.02;  // default Rayleigh damping: this fraction of critical at the first mode (stiffness-proportional)
  double timeStep = 1.0 / 60;  // suggested time step, s
};

// `basis`: full 3n x r in vertex order; `gravity`: r x 3, column a = U^T M e_a.
ModelContents makeModelContents(const CheckedMesh& mesh, const std::vector<Material>& perTet,
                                const Eigen::MatrixXd& basis, const EnergyPolynomial& energy,
                                const std::vector<double>& eigenvalues, const Eigen::MatrixXd& gravity,
                                const ExportSettings& settings);

} // namespace quiver
