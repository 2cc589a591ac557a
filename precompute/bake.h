#pragma once
// The whole bake, stage after stage, on every rank of the BakeContext: load and check the mesh,
// partition, assemble, modes, modal derivatives, basis, reduced polynomials, fidelity, export;
// results go to NAME.qvr
// (the runtime model), NAME.h5 (every stage, written as NAME.h5.partial and renamed when
// complete), NAME.xmf, and with exportNpy NAME.*.npy.
#include <string>
#include <vector>

#include "precompute/bake_context.h"
#include "precompute/stages/basis.h"
#include "precompute/stages/export_model.h"
#include "precompute/stages/fidelity.h"
#include "precompute/stages/mesh.h"
#include "precompute/stages/modes.h"
#include "precompute/stages/surface.h"

namespace quiver {

struct BakeSettings {
  MeshSettings mesh;           // the mesh, its checks, fixed vertices and materials (stages/mesh.h)
  SurfaceSettings surface;     // a surface input's tets, and the render mesh (stages/surface.h)
  int modes = 20;              // k, linear modes
  Eigensolver eigensolver = Eigensolver::Block;  // how the modes are found (stages/modes.h)
  BasisRequest basis;          // r and the recipe, or a user basis (stages/basis.h)
  ExportRequest output;        // NAME, how NAME.qvr stores the model, the .npy exports (stages/export_model.h)
  FidelitySettings fidelity;   // the reduced model against full space at the end (stages/fidelity.h)
  bool resume = false;         // reuse stages of NAME.h5.partial / NAME.h5 whose inputs hash the same
  int threads = 0;             // threads per rank of the stages that start their own; 0: coresPerRank()
  std::string commandLine;     // for provenance
  std::string petscOptions;    // the PETSc/SLEPc options given, part of the modes' input hash
};

// The version the archive records: the CMake project's, which the runtime's QV_VERSION_* match.
const char* bakeVersion();

// Checks that need no mesh: ranges of k, r and material values. Throws std::invalid_argument.
void checkBakeSettings(const BakeSettings& settings);

// Collective. Throws on the first problem (every rank throws the same error for bad inputs).
void runBake(const BakeContext& ctx, const BakeSettings& settings);

} // namespace quiver
