#pragma once
// Stage "fidelity": what the reduced model gets right, measured against the full-space StVK
// reference at the end of the bake, so an artist learns before shipping where it is off.
// Static loads chosen from the mesh, each solved in full space and in the subspace of U with the
// same energy (common/static_equilibrium.h), reported as |u_reduced - u_full| / |u_full|:
// - "own weight": gravity, 9.81 m/s^2 along -z;
// - "pull": the far part (the vertices at least 90% as far from the fixed vertices' centroid as
//   the farthest one) pulled sideways by 10% of the object's size on stiff springs;
// - "twist 30" and "twist 60": the far part turned by 30 and 60 degrees about the line from the
//   fixed vertices' centroid through its own.
// And the reduced frequencies (of U^T K(0) U) against the baked ones. Runs on rank 0 (serial
// sparse solves); a free object has no static equilibrium, so only its frequencies are compared.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "precompute/archive/archive.h"
#include "precompute/stage_runner.h"
#include "precompute/stages/mesh.h"
#include "precompute/stages/modes.h"

namespace quiver {

struct FidelitySettings {
  bool enabled = true;    // --no-fidelity turns the stage off
  int maxTets = 30000;    // --fidelity-max-tets: larger meshes skip it (serial sparse solves: 16 s at 33k tets)
};

struct FidelityCase {
  std::string name;
  double error = 0;                // |u_reduced - u_full| / |u_full|; NaN where no equilibrium was found
  double largestDisplacement = 0;  // of the full-space solution, as a fraction of the bounding box's diagonal
};

struct FidelityReport {
  std::vector<FidelityCase> cases;
  std::vector<double> frequencyErrors;  // reduced / baked - 1, per baked mode (in order)
};

// `basis`: U gathered (3n x r, vertex order, zero rows at fixed DOFs). Collective; writes /fidelity.
FidelityReport fidelityStage(StageRunner& stages, const BakeContext& ctx, const MeshInputs& inputs,
                             const Eigen::MatrixXd& basis, const LinearModes& modes, Archive& archive);

} // namespace quiver
