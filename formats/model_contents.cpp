#include "formats/model_contents.h"

#include <cmath>

#include "common/modal_rotation.h"
#include "common/rigid_body.h"
#include "common/surface.h"

namespace quiver {

ModelContents makeModelContents(const CheckedMesh& mesh, const std::vector<Material>& perTet,
                                const Eigen::MatrixXd& basis, const std::vector<double>& energy,
                                const std::vector<double>& eigenvalues, const Eigen::MatrixXd& gravity,
                                const ExportSettings& settings) {
  const TetMesh& m = mesh.mesh;
  const int r = static_cast<int>(basis.cols());
  ModelContents c;
  ModelInfo& info = c.info;
  info.r = static_cast<uint32_t>(r);
  info.vertexCount = static_cast<uint32_t>(m.vertexCount());
  info.tetCount = static_cast<uint32_t>(m.tetCount());
  info.fileVertexCount = static_cast<uint32_t>(mesh.loadedVertex.size());
  info.eigenvalueCount = static_cast<uint32_t>(eigenvalues.size());
  info.basisPrecision = static_cast<uint32_t>(settings.basisPrecision);

  // Volume-weighted material means; uniform when every tet agrees.
  double volume = 0, E = 0, nu = 0, rho = 0, mass = 0;
  info.materialIsUniform = 1;
  for (int t = 0; t < m.tetCount(); ++t) {
    const double V = std::abs(signedVolume6(m, t)) / 6;
    const Material& mat = perTet[t];
    volume += V;
    E += V * mat.youngsModulus;
    nu += V * mat.poissonRatio;
    rho += V * mat.density;
    mass += V * mat.density;
    const Material& first = perTet[0];
    if (mat.youngsModulus != first.youngsModulus || mat.poissonRatio != first.poissonRatio ||
        mat.density != first.density)
      info.materialIsUniform = 0;
  }
  // Uniform material: its exact values rather than means that round-off has touched.
  info.youngsModulus = info.materialIsUniform ? perTet[0].youngsModulus : E / volume;
  info.poissonRatio = info.materialIsUniform ? perTet[0].poissonRatio : nu / volume;
  info.density = info.materialIsUniform ? perTet[0].density : rho / volume;
  info.totalMass = mass;
  // Stiffness-proportional damping beta K gives the mode of eigenvalue lambda the damping ratio
  // beta sqrt(lambda) / 2: pick beta so the first mode gets dampingRatio.
  info.rayleighAlpha = 0;
  info.rayleighBeta = eigenvalues.empty() ? 0 : 2 * settings.dampingRatio / std::sqrt(eigenvalues[0]);
  info.timeStep = settings.timeStep;
  const auto box = boundingBox(m);
  for (int a = 0; a < 3; ++a) {
    info.bboxMin[a] = box[0][a];
    info.bboxMax[a] = box[1][a];
  }

  c.energy = energy;
  c.basis.resize(basis.size());
  for (Eigen::Index i = 0; i < basis.rows(); ++i)
    for (int j = 0; j < r; ++j) c.basis[i * r + j] = basis(i, j);
  for (const auto& x : m.vertices) c.restPositions.insert(c.restPositions.end(), {x.x(), x.y(), x.z()});
  for (const auto& tri : boundaryTriangles(m))
    for (int v : tri) c.triangles.push_back(static_cast<uint32_t>(v));
  info.triangleCount = static_cast<uint32_t>(c.triangles.size() / 3);
  c.vertexMap.assign(mesh.fileVertex.begin(), mesh.fileVertex.end());
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < r; ++j) c.gravity.push_back(gravity(j, a));
  c.eigenvalues = eigenvalues;
  for (const Tet& t : m.tets)
    for (int v : t) c.tets.push_back(static_cast<uint32_t>(v));
  // Modal rotations for modal warping: each basis vector's vertex rotations (1/2 curl).
  const Eigen::MatrixXd psi = vertexRotations(m, basis);
  c.rotations.resize(psi.size());
  for (Eigen::Index i = 0; i < psi.rows(); ++i)
    for (int j = 0; j < r; ++j) c.rotations[i * r + j] = psi(i, j);
  if (settings.rigidBody) {
    const RigidBodyMoments rb = rigidBodyMoments(m, perTet, basis);
    c.rigidBody.assign(rb.centre.data(), rb.centre.data() + 3);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) c.rigidBody.push_back(rb.secondMoment(a, b));
    for (int ab = 0; ab < 9; ++ab)
      for (int j = 0; j < r; ++j) c.rigidBody.push_back(rb.first(ab, j));
    for (int ab = 0; ab < 9; ++ab)
      for (int j = 0; j < r; ++j)
        for (int k = 0; k < r; ++k) c.rigidBody.push_back(rb.second[ab](j, k));
  }
  return c;
}

ModelContents::RenderMesh makeRenderMesh(const SurfaceMesh::Render& render, const TetMesh& mesh, const Embedding& embedding,
                                         const Eigen::MatrixXd& basis) {
  ModelContents::RenderMesh out;
  out.positions = render.positions;
  out.normals = render.normals;
  out.uvs = render.uvs;
  for (size_t t = 0; t + 2 < render.triangles.size(); t += 3) {
    const uint32_t a = render.triangles[t], b = render.triangles[t + 1], c = render.triangles[t + 2];
    if (a != b && b != c && a != c) out.triangles.insert(out.triangles.end(), {a, b, c});
  }
  const size_t V = render.positions.size() / 3, r = static_cast<size_t>(basis.cols());
  out.basis.reserve(3 * V * r);
  for (size_t i = 0; i < V; ++i) {
    const Tet& tet = mesh.tets[static_cast<size_t>(embedding.tet[i])];
    out.tets.push_back(static_cast<uint32_t>(embedding.tet[i]));
    for (double w : embedding.weights[i]) out.weights.push_back(static_cast<float>(w));
    for (int a = 0; a < 3; ++a)
      for (size_t j = 0; j < r; ++j) {
        double row = 0;
        for (int k = 0; k < 4; ++k) row += embedding.weights[i][k] * basis(3 * tet[k] + a, static_cast<Eigen::Index>(j));
        out.basis.push_back(static_cast<float>(row));
      }
  }
  return out;
}

} // namespace quiver
