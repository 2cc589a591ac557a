#include "common/mass_matrix.h"

#include <cmath>
#include <stdexcept>

namespace quiver {
namespace {

// Both mass matrices have element blocks M_e^{ab} = \rho_e V_e (a == b ? diagonal : offDiagonal) I_3.
Eigen::SparseMatrix<double> assembleMass(const TetMesh& mesh, const std::vector<Material>& perTet,
                                         double diagonal, double offDiagonal) {
  if (static_cast<int>(perTet.size()) != mesh.tetCount())
    throw std::invalid_argument("mass matrix: need one material per tet");
  const int pairsPerTet = offDiagonal == 0 ? 4 : 16;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(mesh.tetCount()) * pairsPerTet * 3);
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const double m = perTet[t].density * std::abs(signedVolume6(mesh, t)) / 6.0;
    const Tet& v = mesh.tets[t];
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        if (a != b && offDiagonal == 0) continue;
        const double value = m * (a == b ? diagonal : offDiagonal);
        for (int c = 0; c < 3; ++c) entries.emplace_back(3 * v[a] + c, 3 * v[b] + c, value);
      }
  }
  const int n = 3 * mesh.vertexCount();
  Eigen::SparseMatrix<double> mass(n, n);
  mass.setFromTriplets(entries.begin(), entries.end());
  return mass;
}

} // namespace

Eigen::SparseMatrix<double> consistentMassMatrix(const TetMesh& mesh, const std::vector<Material>& perTet) {
  return assembleMass(mesh, perTet, consistentMassWeight(0, 0), consistentMassWeight(0, 1));
}

Eigen::SparseMatrix<double> lumpedMassMatrix(const TetMesh& mesh, const std::vector<Material>& perTet) {
  return assembleMass(mesh, perTet, 1.0 / 4.0, 0.0);
}

} // namespace quiver
