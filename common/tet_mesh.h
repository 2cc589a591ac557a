#pragma once
// The linear tetrahedral mesh every part of Quiver works on.
#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/material.h"

namespace quiver {

using Tet = std::array<int, 4>;

struct TetMesh {
  std::vector<Eigen::Vector3d> vertices; // rest positions X
  std::vector<Tet> tets;                 // vertex indices, positively oriented after validation
  std::vector<int> tetRegion;            // per tet: the file's region/physical attribute, 0 when it has none
  std::vector<Material> materials;       // materials the file defines (Vega); empty when it defines none
  std::vector<int> tetMaterial;          // per tet: index into materials; empty when the file assigns none

  int vertexCount() const { return static_cast<int>(vertices.size()); }
  int tetCount() const { return static_cast<int>(tets.size()); }
};

// Six times the signed volume of tet t: det[X1-X0, X2-X0, X3-X0]. Positive when (1,2,3) winds
// counter-clockwise seen from outside the face opposite vertex 0, i.e. the usual orientation.
double signedVolume6(const TetMesh& mesh, int t);

// Sum of |volume| over all tets.
double totalVolume(const TetMesh& mesh);

// Axis-aligned bounding box of the vertices: {min, max}.
std::array<Eigen::Vector3d, 2> boundingBox(const TetMesh& mesh);

// Values given explicitly (e.g. on the command line); each one set replaces that property everywhere.
struct MaterialOverride {
  std::optional<double> youngsModulus, poissonRatio, density;
};

// Per-tet materials: the file's materials where it assigns them, else `fallback`, then `override_`.
std::vector<Material> resolveTetMaterials(const TetMesh& mesh, const Material& fallback,
                                          const MaterialOverride& override_ = {});

} // namespace quiver
