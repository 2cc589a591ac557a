#pragma once
// Stage "basis": the reduced basis U (free DOFs x r), M-orthonormal (U^T M U = I).
// From the bake's own vectors: linear modes scaled by lambda_1 / lambda_i and modal derivatives
// scaled by lambda_1^2 / (lambda_i lambda_j) (Barbič & James 2005), then mass-PCA: the r dominant
// directions of that set in the M inner product. Derivatives with i != j carry an extra sqrt(2):
// Psi_ij stands for both Psi_ij and Psi_ji, and with that weight the basis no longer depends on
// how an eigensolver picks vectors inside a repeated eigenvalue's eigenspace.
// Or from the user (--basis-from): any full-rank set of columns, M-orthonormalised.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <petscmat.h>

#include "precompute/dof_layout.h"
#include "precompute/stages/modal_derivatives.h"
#include "precompute/stages/modes.h"

namespace quiver {

struct BasisSettings {
  int rank = 30;                          // r, basis vectors kept (>= 1)
  double maxOrthonormalityError = 1e-10;  // refuse a basis with max |U^T M U - I| above this
};

struct ReducedBasis {
  Eigen::MatrixXd vectors;               // this rank's rows, r columns, M-orthonormal, oriented
  std::vector<double> singularValues;    // mass-PCA singular values, descending (all of them)
  double orthonormalityError = 0;        // max |U^T M U - I|
};

// Collective. Throws when the scaled set has fewer than r independent directions.
ReducedBasis buildBasis(Mat mass, const DofLayout& layout, const LinearModes& modes,
                        const ModalDerivatives& derivatives, const BasisSettings& settings);

// M-orthonormalises a user basis given as this rank's rows. `wasOrthonormal` reports whether
// it already was (max |U^T M U - I| <= 1e-8). Throws when its columns are not independent.
ReducedBasis importBasis(Mat mass, const DofLayout& layout, Eigen::MatrixXd rows, bool& wasOrthonormal);

// U <- U L^{-T} with U^T M U = L L^T; returns max |U^T M U - I| afterwards. Collective.
double massOrthonormalize(Mat mass, const DofLayout& layout, Eigen::MatrixXd& U);

} // namespace quiver
