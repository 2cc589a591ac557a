#pragma once
// Tetrahedralizing a checked closed surface with Gmsh, run as a separate program (Gmsh is GPL:
// the bake never links it; Debian's `gmsh` package provides it). Gmsh remeshes the surface at the
// target edge length without a CAD model (ClassifySurfaces / CreateGeometry, as in its tutorial
// t13), fills it with tets (Delaunay) and optimises them (its own and Netgen's optimisers). The
// result must reach a floor on the smallest dihedral angle (neither Gmsh nor TetGen guarantees one:
// it is measured); two more runs are tried (stronger optimisation, a 2% larger edge), then the bake
// stops with the numbers. Measured: smooth closed shapes reach 9-19 degrees.
#include <string>

#include "common/surface_check.h"
#include "common/tet_mesh.h"

namespace quiver {

struct MesherSettings {
  int targetTets = 5000;        // about this many tets (used when edgeLength is 0)
  double edgeLength = 0;        // m; 0: from targetTets and the enclosed volume
  double minDihedral = 5;       // degrees: every tet at least this (checked on the result)
  double timeLimit = 3600;      // s per gmsh run: a run past it stops the bake (a hung gmsh held it forever)
  std::string program = "gmsh";
};

struct MesherResult {
  TetMesh mesh;
  double edgeLength = 0;   // m, the target Gmsh was given (last run)
  double minDihedral = 0;  // degrees, measured
  double seconds = 0;      // wall time of the runs
  int runs = 0;
};

// Throws MeshError "NAME: ..." when Gmsh is missing, fails (with its last message), runs past the
// time limit or cannot reach the quality floor.
MesherResult tetrahedralize(const CheckedSurface& surface, const MesherSettings& settings, const std::string& name);

} // namespace quiver
