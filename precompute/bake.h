#pragma once
// The whole bake, stage after stage, on every rank of the BakeContext: load and check the mesh,
// partition, assemble, modes, modal derivatives, basis, reduced polynomials; results go to NAME.qvr
// (the runtime model), NAME.h5 (every stage, written as NAME.h5.partial and renamed when
// complete), NAME.xmf, and with exportNpy NAME.*.npy.
#include <string>
#include <vector>

#include "common/tet_mesh.h"
#include "common/fixed_vertices.h"
#include "common/mesh_checks.h"
#include "precompute/bake_context.h"
#include "precompute/stages/basis.h"
#include "formats/model_contents.h"

namespace quiver {

struct BakeSettings {
  std::string meshPath;
  MeshCheckOptions checks;
  FixedVertexRequest fixed;
  MaterialOverride material;   // explicit values win over the mesh file's
  Material fallback;           // where neither the file nor the command line gives one
  int modes = 20;              // k, linear modes
  int rank = 30;               // r, basis vectors
  BasisKind basisKind = BasisKind::Pca;  // the recipe from modes and derivatives (precompute/stages/basis.h)
  bool exactRank = false;      // fail rather than bake fewer than `rank` vectors when the recipe gives fewer
  std::string basisFrom;       // user basis: FILE.npy (3N x r) or FILE.h5:/dataset; "" for none
  bool exportNpy = false;      // also write NAME.eigenvalues.npy, NAME.modes.npy, NAME.U.npy
  ExportSettings model;        // how NAME.qvr stores the basis, default damping and time step
  bool resume = false;         // reuse stages of NAME.h5.partial / NAME.h5 whose inputs hash the same
  std::string output;          // NAME
  std::string commandLine;     // for provenance
  std::string petscOptions;    // the PETSc/SLEPc options given, part of the modes' input hash
};

// Checks that need no mesh: ranges of k, r and material values. Throws std::invalid_argument.
void checkBakeSettings(const BakeSettings& settings);

// Collective. Throws on the first problem (every rank throws the same error for bad inputs).
void runBake(const BakeContext& ctx, const BakeSettings& settings);

} // namespace quiver
