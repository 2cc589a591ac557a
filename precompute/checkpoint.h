#pragma once
// Each bake stage's results in the archive (schema: formats/ARCHIVE.md), and back. A stage group
// counts as complete only once its `input_hash` attribute is written, which happens last: a
// bake killed half-way leaves groups without it, and --resume recomputes those.
#include <string>

#include "common/tet_mesh.h"
#include "common/mesh_checks.h"
#include "precompute/archive/archive.h"
#include "precompute/dof_layout.h"
#include "precompute/stages/basis.h"
#include "precompute/stages/modal_derivatives.h"
#include "precompute/stages/modes.h"
#include "precompute/stages/partition.h"
#include "precompute/stages/polynomials.h"

namespace quiver {

// The stage's stored input hash, or "" when the group is missing or incomplete.
std::string storedInputHash(const Archive& archive, const std::string& group);

// /mesh, /material, /constraints and /partition: the inputs, rewritten on every run.
void writeInputs(Archive& archive, const CheckedMesh& mesh, const std::string& sourceFile,
                 const std::vector<Material>& perTet, const std::vector<int>& fixedVertices,
                 const Partition& partition, int ranks);

void writeModes(Archive& archive, const LinearModes& modes, const DofLayout& layout, const std::string& inputHash);
LinearModes readModes(const Archive& archive, const DofLayout& layout);

void writeDerivatives(Archive& archive, const ModalDerivatives& derivatives, const DofLayout& layout,
                      const std::string& inputHash);
ModalDerivatives readDerivatives(const Archive& archive, const DofLayout& layout);

void writeBasis(Archive& archive, const ReducedBasis& basis, const std::string& source, const DofLayout& layout,
                const std::string& inputHash);
ReducedBasis readBasis(const Archive& archive, const DofLayout& layout);

void writePolynomial(Archive& archive, const EnergyPolynomial& energy, const std::string& inputHash);
EnergyPolynomial readPolynomial(const Archive& archive);

// Distributed vectors as (columns, vertices, 3) datasets, zeros at fixed DOFs. Collective.
void writeVectors(Archive& archive, const std::string& dataset, const Eigen::MatrixXd& local, const DofLayout& layout);
Eigen::MatrixXd readVectors(const Archive& archive, const std::string& dataset, const DofLayout& layout);

} // namespace quiver
