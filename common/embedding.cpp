#include "common/embedding.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "common/mesh_error.h"

namespace quiver {

namespace {

using Vec = Eigen::Vector3d;

// Each tet's inverse edge matrix, once: barycentric weights are then one product.
std::vector<Eigen::Matrix3d> inverseEdges(const TetMesh& m) {
  std::vector<Eigen::Matrix3d> out(m.tets.size());
  for (size_t t = 0; t < m.tets.size(); ++t) {
    Eigen::Matrix3d D;
    for (int k = 0; k < 3; ++k) D.col(k) = m.vertices[m.tets[t][k + 1]] - m.vertices[m.tets[t][0]];
    out[t] = D.inverse();
  }
  return out;
}

std::array<double, 4> barycentric(const TetMesh& m, const std::vector<Eigen::Matrix3d>& inverse, int t, const Vec& p) {
  const Vec b = inverse[t] * (p - m.vertices[m.tets[t][0]]);
  return {1 - b.sum(), b[0], b[1], b[2]};
}

// The closest point to p of triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
Vec closestOnTriangle(const Vec& p, const Vec& a, const Vec& b, const Vec& c) {
  const Vec ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Vec cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// The closest point of tet t to p (p itself when inside).
Vec closestOnTet(const TetMesh& m, int t, const Vec& p, const std::array<double, 4>& w) {
  if (*std::min_element(w.begin(), w.end()) >= 0) return p;
  const Tet& v = m.tets[t];
  Vec best = m.vertices[v[0]];
  for (int skip = 0; skip < 4; ++skip) {
    Vec corner[3];
    for (int k = 0, j = 0; k < 4; ++k)
      if (k != skip) corner[j++] = m.vertices[v[k]];
    const Vec q = closestOnTriangle(p, corner[0], corner[1], corner[2]);
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  }
  return best;
}

} // namespace

Embedding embedPoints(const TetMesh& mesh, const std::vector<double>& points, double tolerance, const std::string& name) {
  // A uniform grid of the tets' boxes, cells about a mean edge wide.
  Eigen::AlignedBox3d all;
  double edges = 0;
  for (const Tet& t : mesh.tets)
    for (int k = 0; k < 4; ++k) all.extend(mesh.vertices[t[k]]), edges += (mesh.vertices[t[k]] - mesh.vertices[t[(k + 1) % 4]]).norm();
  const double cell = std::max(edges / (4.0 * mesh.tets.size()), all.diagonal().maxCoeff() / 512);
  Eigen::Array3i cells;
  for (int a = 0; a < 3; ++a) cells[a] = std::max(1, static_cast<int>(std::ceil(all.diagonal()[a] / cell)));
  const auto index = [&](const Vec& p, int a) {
    return std::clamp(static_cast<int>(std::floor((p[a] - all.min()[a]) / cell)), 0, cells[a] - 1);
  };
  std::vector<std::vector<int>> grid(static_cast<size_t>(cells.prod()));
  const std::vector<Eigen::Matrix3d> inverse = inverseEdges(mesh);
  std::vector<Eigen::AlignedBox3d> boxes(mesh.tets.size());
  const auto slot = [&](int x, int y, int z) { return (static_cast<size_t>(z) * cells[1] + y) * cells[0] + x; };
  for (int t = 0; t < mesh.tetCount(); ++t) {
    Eigen::AlignedBox3d& box = boxes[t];
    for (int k = 0; k < 4; ++k) box.extend(mesh.vertices[mesh.tets[t][k]]);
    for (int z = index(box.min(), 2); z <= index(box.max(), 2); ++z)
      for (int y = index(box.min(), 1); y <= index(box.max(), 1); ++y)
        for (int x = index(box.min(), 0); x <= index(box.max(), 0); ++x) grid[slot(x, y, z)].push_back(t);
  }
  Embedding out;
  const size_t count = points.size() / 3;
  out.tet.resize(count);
  out.weights.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const Vec p(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
    // The containing tet (the one whose smallest weight is largest), else the nearest within reach.
    int best = -1;
    double bestDistance = std::numeric_limits<double>::infinity(), bestInside = -std::numeric_limits<double>::infinity();
    std::array<double, 4> bestWeights{};
    // Shells of cells around p's, nearest first, until no farther shell can hold a nearer tet.
    const int px = index(p, 0), py = index(p, 1), pz = index(p, 2);
    const int rings = static_cast<int>(std::ceil(tolerance / cell)) + 1;
    const auto visit = [&](int x, int y, int z) {
      if (x < 0 || y < 0 || z < 0 || x >= cells[0] || y >= cells[1] || z >= cells[2]) return;
      for (int t : grid[slot(x, y, z)]) {
        if (boxes[t].exteriorDistance(p) > bestDistance) continue;  // cannot be nearer
        const std::array<double, 4> w = barycentric(mesh, inverse, t, p);
        const double inside = *std::min_element(w.begin(), w.end());
        const double distance = inside >= 0 ? 0.0 : (closestOnTet(mesh, t, p, w) - p).norm();
        if (distance < bestDistance || (distance == 0 && inside > bestInside))
          best = t, bestDistance = distance, bestInside = inside, bestWeights = w;
      }
    };
    if (all.exteriorDistance(p) <= tolerance)
      for (int k = 0; k <= rings && !(bestDistance < (k - 1) * cell); ++k)
        for (int z = pz - k; z <= pz + k; ++z)
          for (int y = py - k; y <= py + k; ++y)
            for (int x = px - k; x <= px + k; ++x)
              if (std::max({std::abs(x - px), std::abs(y - py), std::abs(z - pz)}) == k) visit(x, y, z);
    if (best < 0 || bestDistance > tolerance) {
      char text[256];
      if (best < 0)
        std::snprintf(text, sizeof text, "%s: point %zu (%.6g, %.6g, %.6g) is more than the tolerance %.3g m from every tet",
                      name.c_str(), i, p[0], p[1], p[2], tolerance);
      else
        std::snprintf(text, sizeof text, "%s: point %zu (%.6g, %.6g, %.6g) is %.3g m from the nearest tet, beyond the tolerance %.3g m",
                      name.c_str(), i, p[0], p[1], p[2], bestDistance, tolerance);
      throw MeshError(text);
    }
    if (bestDistance > 0) {
      ++out.outside;
      out.farthest = std::max(out.farthest, bestDistance);
      const bool tame = std::all_of(bestWeights.begin(), bestWeights.end(), [](double w) { return w >= -0.5 && w <= 1.5; });
      if (!tame) bestWeights = barycentric(mesh, inverse, best, closestOnTet(mesh, best, p, bestWeights));
    }
    out.tet[i] = best;
    out.weights[i] = bestWeights;
  }
  return out;
}

} // namespace quiver
