#include "common/tet_mesh.h"

#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/LU>

namespace quiver {

std::string checkMaterial(const Material& m) {
  std::ostringstream why;
  if (!(std::isfinite(m.youngsModulus) && m.youngsModulus > 0))
    why << "Young's modulus E = " << m.youngsModulus << " Pa must be > 0";
  else if (!(m.poissonRatio > -1.0 && m.poissonRatio < 0.5))
    why << "Poisson ratio nu = " << m.poissonRatio << " must lie in (-1, 0.5)";
  else if (!(std::isfinite(m.density) && m.density > 0))
    why << "density = " << m.density << " kg/m^3 must be > 0";
  return why.str();
}

double signedVolume6(const TetMesh& mesh, int t) {
  const Tet& v = mesh.tets[t];
  const Eigen::Vector3d& x0 = mesh.vertices[v[0]];
  Eigen::Matrix3d dm;
  dm << mesh.vertices[v[1]] - x0, mesh.vertices[v[2]] - x0, mesh.vertices[v[3]] - x0;
  return dm.determinant();
}

double totalVolume(const TetMesh& mesh) {
  double sum = 0;
  for (int t = 0; t < mesh.tetCount(); ++t) sum += std::abs(signedVolume6(mesh, t)) / 6.0;
  return sum;
}

std::array<Eigen::Vector3d, 2> boundingBox(const TetMesh& mesh) {
  const double inf = std::numeric_limits<double>::infinity();
  std::array<Eigen::Vector3d, 2> box{Eigen::Vector3d::Constant(inf), Eigen::Vector3d::Constant(-inf)};
  for (const auto& x : mesh.vertices) {
    box[0] = box[0].cwiseMin(x);
    box[1] = box[1].cwiseMax(x);
  }
  return box;
}

std::vector<Material> resolveTetMaterials(const TetMesh& mesh, const Material& fallback,
                                          const MaterialOverride& override_) {
  std::vector<Material> out(mesh.tets.size(), fallback);
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    if (!mesh.tetMaterial.empty()) out[t] = mesh.materials[mesh.tetMaterial[t]];
    if (override_.youngsModulus) out[t].youngsModulus = *override_.youngsModulus;
    if (override_.poissonRatio) out[t].poissonRatio = *override_.poissonRatio;
    if (override_.density) out[t].density = *override_.density;
  }
  return out;
}

} // namespace quiver
