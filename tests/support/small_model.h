#pragma once
// A small model made the way the bake makes one, from common/ and formats/ alone (dense Eigen
// instead of PETSc/SLEPc/MPI): a cantilever beam clamped at x = 0, its lowest modes and their
// modal derivatives (or, free, its lowest elastic modes and theirs), mass-PCA into U, and the exact reduced StVK energy of U. The runtime's and
// the tools' tests load it, so they build and run without the bake.
#include <array>
#include <string>

#include <Eigen/Core>

#include "common/material.h"
#include "formats/model/qvr_writer.h"

namespace quiver::test {

struct SmallModelSpec {
  Eigen::Vector3d size{0.6, 0.1, 0.1};  // m
  std::array<int, 3> cells{12, 2, 2};
  double youngsModulus = 1e6, poissonRatio = 0.4, density = 1000;
  int modes = 6;         // k lowest modes and their k(k+1)/2 derivatives
  // The amplitude (m sqrt(kg)) the derivatives are weighed at. The bake takes a fraction of the
  // object's extent, 0.3 ||X - c||_M (0.13 for the default beam), since its basis 2; before, 1
  // whatever the object. The suite's models keep 1: the runtime tests' figures were measured on
  // those bases, and the runtime must step any M-orthonormal basis (--basis-from bakes one). What
  // it does on the bake's own basis for these beams: docs/architecture.md, "Bases".
  double derivativeAmplitude = 1;
  int rank = 10;         // r
  int basisPrecision = 64;
  bool free = false;     // no clamped face: the six rigid motions are left out of the basis, and the
                         // model carries its mass moments (RIGID_BODY) to fly
};

ModelContents smallBeamModel(const SmallModelSpec& spec = {});

} // namespace quiver::test
