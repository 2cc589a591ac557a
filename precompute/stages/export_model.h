#pragma once
// Stage "export": NAME.qvr, the runtime model (formats/model_contents.h), from the bake's results,
// the gravity projection U^T M e_a computed here and the fidelity report (its FIDELITY section); with exportNpy also NAME.eigenvalues.npy,
// NAME.modes.npy and NAME.U.npy (3N rows in the mesh file's vertex order). Collective; rank 0 writes.
#include <string>

#include <Eigen/Core>

#include "formats/model_contents.h"
#include "precompute/bake_context.h"
#include "precompute/dof_layout.h"
#include "precompute/stages/fidelity.h"
#include "precompute/stages/mesh.h"
#include "precompute/stages/modes.h"
#include "precompute/stages/polynomials.h"
#include "precompute/stages/surface.h"

namespace quiver {

struct ExportRequest {
  std::string name;          // NAME
  ExportSettings model;      // how NAME.qvr stores the basis, default damping and time step
  bool exportNpy = false;
};

// `fullU`: the basis gathered to every rank (3n x r, vertex order). Returns the .qvr's path.
std::string exportModel(const BakeContext& ctx, const ExportRequest& request, const MeshInputs& inputs,
                        const DofLayout& layout, const LinearModes& modes,
                        const Eigen::MatrixXd& fullU, const EnergyPolynomial& energy, const FidelityReport& fidelity,
                        const RenderInputs& render);

} // namespace quiver
