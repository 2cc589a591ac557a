#pragma once
// Stage "mesh": every rank reads and checks the same file (so every rank fails alike), selects the
// fixed vertices, resolves each tet's material, and hashes all of it: the input of every later
// stage's hash.
#include <cstdint>
#include <string>
#include <vector>

#include "common/fixed_vertices.h"
#include "common/material.h"
#include "common/mesh_checks.h"
#include "precompute/archive/archive.h"
#include "precompute/bake_context.h"

namespace quiver {

struct MeshSettings {
  std::string path;
  MeshCheckOptions checks;
  FixedVertexRequest fixed;
  MaterialOverride material;  // explicit values win over the mesh file's
  Material fallback;          // where neither the file nor the command line gives one
};

struct MeshInputs {
  CheckedMesh mesh;
  std::vector<int> fixed;       // loaded-vertex indices
  std::vector<Material> perTet;
  std::string hash;             // of the file's bytes, the checks, the fixed vertices and the materials
  int64_t freeDofs = 0;
  bool freeObject() const { return fixed.empty(); }
};

// Throws MeshError / std::invalid_argument naming the file and the problem.
MeshInputs loadMeshInputs(const MeshSettings& settings);

// Rank 0 warns on stderr: what the checks repaired, and a mesh without materials whose values the
// command line leaves to the defaults.
void warnAboutMesh(const BakeContext& ctx, const MeshInputs& inputs, const MeshSettings& settings);

// Checkpoint: groups /mesh, /material and /constraints, rewritten on every run; the bake never
// reads them back (later stages' hashes build on `inputs.hash`). `sourceFile` is recorded as given.
void writeMeshInputs(Archive& archive, const MeshInputs& inputs, const std::string& sourceFile);

// Progress: "189 vertices, 480 tets, 9 fixed vertices, 540 free DOFs".
std::string describeMesh(const MeshInputs& inputs);

} // namespace quiver
