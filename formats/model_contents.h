#pragma once
// The contents of a runtime model (formats/model/QVR.md) from what a bake computed: energy
// coefficients, basis rows, rest positions, surface triangles, the vertex map back to the mesh
// file, the gravity projection U^T M e_a, eigenvalues, material, default damping, and the modal
// rotations (1/2 curl of each basis vector at the vertices) for modal warping. The bake's export
// stage writes them; tests build small models with them.
#include <vector>

#include <Eigen/Core>

#include "common/embedding.h"
#include "common/mesh_checks.h"
#include "formats/mesh/read_surface.h"
#include "formats/model/qvr_writer.h"

namespace quiver {

struct ExportSettings {
  int basisPrecision = 32;   // bits per stored basis entry: 32 (default, half the size) or 64
  double dampingRatio = 0.02;  // default Rayleigh damping: this fraction of critical at the first mode (stiffness-proportional)
  double timeStep = 1.0 / 60;  // suggested time step, s
  bool rigidBody = false;      // a free object: store its mass moments (RIGID_BODY) for flight
};

// `basis`: full 3n x r in vertex order; `energy`: the ENERGY_COEFFICIENTS of that basis (see
// energyCoefficientsFromGram); `gravity`: r x 3, column a = U^T M e_a.
ModelContents makeModelContents(const CheckedMesh& mesh, const std::vector<Material>& perTet,
                                const Eigen::MatrixXd& basis, const std::vector<double>& energy,
                                const std::vector<double>& eigenvalues, const Eigen::MatrixXd& gravity,
                                const ExportSettings& settings);

// The RENDER_MESH of `render` (a surface as the file gives it) bound to the tets by `embedding`:
// render basis rows W U from `basis` (3n x r). Triangles with a repeated corner are left out.
ModelContents::RenderMesh makeRenderMesh(const SurfaceMesh::Render& render, const TetMesh& mesh, const Embedding& embedding,
                                         const Eigen::MatrixXd& basis);

} // namespace quiver
