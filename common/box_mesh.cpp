#include "common/box_mesh.h"

#include <algorithm>
#include <stdexcept>

namespace quiver {

TetMesh makeBoxMesh(const Eigen::Vector3d& size, const std::array<int, 3>& cells) {
  for (int d = 0; d < 3; ++d)
    if (!(size[d] > 0) || cells[d] < 1) throw std::invalid_argument("makeBoxMesh: size must be > 0 and cells >= 1");
  const int nx = cells[0] + 1, ny = cells[1] + 1, nz = cells[2] + 1;
  auto id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };

  TetMesh mesh;
  mesh.vertices.reserve(static_cast<size_t>(nx) * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        mesh.vertices.emplace_back(size.x() * i / cells[0], size.y() * j / cells[1], size.z() * k / cells[2]);

  // The six axis orders; walking corner 000 -> 111 one axis at a time gives one tet each.
  std::array<int, 3> axes{0, 1, 2};
  std::array<std::array<int, 3>, 6> orders;
  for (auto& o : orders) {
    o = axes;
    std::next_permutation(axes.begin(), axes.end());
  }
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i)
        for (const auto& o : orders) {
          std::array<int, 3> c{i, j, k};
          Tet t;
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[o[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          mesh.tets.push_back(t);
          if (signedVolume6(mesh, mesh.tetCount() - 1) < 0) std::swap(mesh.tets.back()[1], mesh.tets.back()[2]);
        }
  mesh.tetRegion.assign(mesh.tets.size(), 0);
  return mesh;
}

} // namespace quiver
