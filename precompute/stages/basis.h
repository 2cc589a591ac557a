#pragma once
// Stage "basis": the reduced basis U (free DOFs x r), M-orthonormal (U^T M U = I). Three recipes
// from the bake's own vectors (--basis), or the user's (--basis-from):
// - pca (default; Barbič & James 2005): linear modes scaled by lambda_1 / lambda_i and modal
//   derivatives scaled by lambda_1^2 / (lambda_i lambda_j), then mass-PCA: the r dominant
//   directions of that set in the M inner product. Each derivative is also taken at an amplitude
//   of pcaAmplitude times the object's extent ||X - c||_M (objectExtent()): a derivative is a
//   displacement per squared amplitude and a mode one per amplitude, so without it the basis
//   depended on the object's size and density (a bar 7x as long or 40x as dense got another
//   basis). The fraction trades large deformations for frequencies (README, "basis"); its default,
//   0.3, moves the object by about the fidelity report's loads (10-40% of its size) and held most
//   of both on the three meshes measured. Derivatives with i != j carry an extra sqrt(2):
//   Psi_ij stands for both Psi_ij and Psi_ji, and with that weight the basis no longer depends on
//   how an eigensolver picks vectors inside a repeated eigenvalue's eigenspace. Buys: the best
//   r-dimensional fit to the weighted set, so large bending; but it may drop higher modes (the
//   weights rank their derivatives' bending above them), and where the spectrum spans many
//   decades the weights fall below what the mass-PCA can resolve (1e-7 of the largest).
// - keep-modes: the k modes exactly, then the derivatives in the order of those weights, each
//   M-orthogonalised against what is already in and kept while it adds a direction (1e-6 of its
//   own norm). Buys: every baked frequency reproduced exactly (twist included), and independence
//   judged per vector, so spectra spread over any range are fine.
// - modes: the first r modes. Buys: linear modal accuracy and the cheapest bake (no
//   derivatives); large deformations stay linear-looking.
// When the recipe yields fewer independent vectors than r, the basis has as many as it yields and
// says so in `warning` (or, with exactRank, the stage fails).
#include <string>
#include <vector>

#include <Eigen/Core>
#include <petscmat.h>

#include "common/material.h"
#include "common/mesh_checks.h"
#include "common/tet_mesh.h"
#include "precompute/archive/archive.h"
#include "precompute/bake_context.h"
#include "precompute/dof_layout.h"
#include "precompute/stages/modal_derivatives.h"
#include "precompute/stages/modes.h"

namespace quiver {

enum class BasisKind { Pca, KeepModes, Modes };
// "pca", "keep-modes", "modes"; the recipe's name in messages and the archive.
const char* basisKindName(BasisKind kind);

struct BasisSettings {
  int rank = 30;                          // r, basis vectors wanted (>= 1)
  BasisKind kind = BasisKind::Pca;
  bool exactRank = false;                 // fail rather than bake fewer than r vectors
  double pcaAmplitude = 0.3;              // pca: the derivatives' amplitude, a fraction of objectExtent() (> 0)
  double maxOrthonormalityError = 1e-10;  // refuse a basis with max |U^T M U - I| above this
};

struct ReducedBasis {
  Eigen::MatrixXd vectors;               // this rank's rows, r columns, M-orthonormal, oriented
  std::vector<double> singularValues;    // mass-PCA singular values, descending (all of them)
  double orthonormalityError = 0;        // max |U^T M U - I|
  std::string warning;                   // why r is smaller than asked, or ""
};

// The object's extent in the mass norm, sqrt(\int rho |X - c|^2) about its centre of mass c: the
// modal amplitude that moves it, in the mean, by its own radius of gyration.
double objectExtent(const TetMesh& mesh, const std::vector<Material>& perTet);

// Collective. `derivatives` may be empty for BasisKind::Modes; `extent`, objectExtent(), is used
// by BasisKind::Pca. Throws when the recipe yields fewer than r vectors and settings.exactRank is
// set.
ReducedBasis buildBasis(Mat mass, const DofLayout& layout, const LinearModes& modes,
                        const ModalDerivatives& derivatives, double extent, const BasisSettings& settings);

// The stage as the bake runs it: the recipe from the modes (and derivatives), or the user's basis
// (`userBasis` not empty: FILE.npy or FILE.h5:/dataset, given loaded as `user`, loadUserBasis()),
// written to the archive's /basis. Rank 0 warns on stderr when r is smaller than asked or a user
// basis was not M-orthonormal.
struct BasisRequest {
  BasisSettings settings;
  std::string userBasis;
};
ReducedBasis bakeBasis(const BakeContext& ctx, const BasisRequest& request, const Eigen::MatrixXd& user, Mat mass,
                       const DofLayout& layout, const LinearModes& modes, const ModalDerivatives& derivatives,
                       double extent, Archive& archive, const std::string& inputHash);

// A user basis (--basis-from FILE.npy of shape (3N, r), or FILE.h5:/dataset of shape (r, N, 3), N
// in the mesh file's vertex order) as a full 3n x r matrix in the loaded mesh's vertex order.
// Collective. Throws naming the file and the shape it expected.
Eigen::MatrixXd loadUserBasis(MPI_Comm comm, const std::string& spec, const CheckedMesh& mesh);

// M-orthonormalises a user basis given as this rank's rows. `wasOrthonormal` reports whether
// it already was (max |U^T M U - I| <= 1e-8). Throws when its columns are not independent.
ReducedBasis importBasis(Mat mass, const DofLayout& layout, Eigen::MatrixXd rows, bool& wasOrthonormal);

// U <- U L^{-T} with U^T M U = L L^T; returns max |U^T M U - I| afterwards. Collective.
double massOrthonormalize(Mat mass, const DofLayout& layout, Eigen::MatrixXd& U);

// Checkpoint: group /basis. Input hash: the derivatives' (the modes' for BasisKind::Modes), r, the
// recipe, exactRank, pcaAmplitude (pca only) and the stage's version tag; for a user basis, the mesh
// stage's, the basis's spec and a version tag of its own.
inline constexpr const char* kBasisVersion = "basis 2";
inline constexpr const char* kUserBasisVersion = "user basis 1";
std::string basisInputHash(const std::string& vectorsHash, const BasisSettings& settings);
std::string userBasisInputHash(const std::string& meshHash, const std::string& spec);
// `source`: the recipe's name or the user basis's spec.
void writeBasis(Archive& archive, const ReducedBasis& basis, const std::string& source, const DofLayout& layout,
                const std::string& inputHash);
ReducedBasis readBasis(const Archive& archive, const DofLayout& layout);
// Progress: "r = 30, max |U^T M U - I| = 6e-16".
std::string describeBasis(const ReducedBasis& basis);

} // namespace quiver
