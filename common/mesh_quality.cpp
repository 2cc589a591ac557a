#include "common/mesh_quality.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace quiver {

namespace {

// Accumulates min, mean and max of a stream of values.
class RangeBuilder {
public:
  void add(double v) {
    lo_ = std::min(lo_, v);
    hi_ = std::max(hi_, v);
    sum_ += v;
    ++n_;
  }
  Range range() const { return n_ ? Range{lo_, sum_ / n_, hi_} : Range{}; }

private:
  double lo_ = std::numeric_limits<double>::infinity(), hi_ = -lo_, sum_ = 0;
  long n_ = 0;
};

} // namespace

MeshQuality measureQuality(const TetMesh& mesh) {
  RangeBuilder normalised, dihedral, edge, volume;
  const double pi = std::acos(-1.0);
  static const int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const Tet& v = mesh.tets[t];
    const double vol6 = signedVolume6(mesh, t);
    double sumSq = 0;
    for (const auto& e : edges) {
      const double len = (mesh.vertices[v[e[0]]] - mesh.vertices[v[e[1]]]).norm();
      edge.add(len);
      sumSq += len * len;
    }
    const double lrms = std::sqrt(sumSq / 6);
    normalised.add(lrms > 0 ? std::sqrt(2.0) * vol6 / (lrms * lrms * lrms) : 0.0);
    volume.add(vol6 / 6);
    // Outward face normals n_i (face opposite vertex i); the dihedral angle at the edge shared
    // by faces i and j is pi minus the angle between their outward normals.
    Eigen::Vector3d n[4];
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d& a = mesh.vertices[v[(i + 1) % 4]];
      const Eigen::Vector3d& b = mesh.vertices[v[(i + 2) % 4]];
      const Eigen::Vector3d& c = mesh.vertices[v[(i + 3) % 4]];
      n[i] = (b - a).cross(c - a);
      if (n[i].dot(mesh.vertices[v[i]] - a) > 0) n[i] = -n[i];
      n[i].normalize();
    }
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        dihedral.add((pi - std::acos(std::clamp(n[i].dot(n[j]), -1.0, 1.0))) * 180 / pi);
  }
  return {normalised.range(), dihedral.range(), edge.range(), volume.range()};
}

} // namespace quiver
