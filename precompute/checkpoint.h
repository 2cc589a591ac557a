#pragma once
// What every stage's checkpoint in the archive (schema: formats/ARCHIVE.md) is made of; each stage
// file writes and reads its own group with these. A stage group counts as complete only once its
// `input_hash` attribute is written, which happens last (finishGroup): a bake killed half-way
// leaves groups without it, and --resume recomputes those.
#include <string>

#include "precompute/archive/archive.h"
#include "precompute/dof_layout.h"

namespace quiver {

// The stage's stored input hash, or "" when the group is missing or incomplete.
std::string storedInputHash(const Archive& archive, const std::string& group);

// Starts a stage group afresh (whatever a killed run left there goes first); finishes it by
// writing its input hash last.
void resetGroup(Archive& archive, const std::string& group);
void finishGroup(Archive& archive, const std::string& group, const std::string& inputHash);

// Replicated 1-D float64 datasets.
void writeVector(Archive& archive, const std::string& dataset, const std::vector<double>& values);
std::vector<double> readVector(const Archive& archive, const std::string& dataset);

// Distributed vectors as (columns, vertices, 3) datasets, zeros at fixed DOFs. Collective.
void writeVectors(Archive& archive, const std::string& dataset, const Eigen::MatrixXd& local, const DofLayout& layout);
Eigen::MatrixXd readVectors(const Archive& archive, const std::string& dataset, const DofLayout& layout);

} // namespace quiver
