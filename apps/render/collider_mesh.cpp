#include "apps/render/collider_mesh.h"

#include <cmath>

#include <Eigen/Geometry>

namespace quiver::app {

namespace {

unsigned addVertex(TriangleSoup& soup, const Eigen::Vector3d& p) {
  for (int a = 0; a < 3; ++a) soup.positions.push_back(static_cast<float>(p[a]));
  return static_cast<unsigned>(soup.positions.size() / 3 - 1);
}

void addQuad(TriangleSoup& soup, unsigned a, unsigned b, unsigned c, unsigned d) {
  soup.triangles.insert(soup.triangles.end(), {a, b, c, a, c, d});
}

// The points `centre + radius * (cos phi sin theta, sin phi sin theta, cos theta)` in the frame
// (x, y, axis), theta from 0 to pi (rings) and phi around (segments); `stretch` moves the upper
// half (theta < pi / 2) along the axis: a capsule.
void addRoundShape(TriangleSoup& soup, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis, double radius,
                   double stretch) {
  constexpr int kRings = 12, kSegments = 20;
  const Eigen::Vector3d z = axis.normalized();
  const Eigen::Vector3d x = z.unitOrthogonal(), y = z.cross(x);
  const unsigned first = static_cast<unsigned>(soup.positions.size() / 3);
  for (int i = 0; i <= kRings; ++i) {
    const double theta = M_PI * i / kRings;
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * M_PI * j / kSegments;
      const Eigen::Vector3d d = std::sin(theta) * (std::cos(phi) * x + std::sin(phi) * y) + std::cos(theta) * z;
      addVertex(soup, centre + radius * d + (2 * i <= kRings ? stretch : 0.0) * z);
    }
  }
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j < kSegments; ++j) {
      const unsigned a = first + i * kSegments + j, b = first + i * kSegments + (j + 1) % kSegments;
      addQuad(soup, a, a + kSegments, b + kSegments, b);
    }
}

} // namespace

void appendCollider(const qv_collider& c, const SurfaceMesh* surface, const Eigen::Vector3d& boxMin,
                    const Eigen::Vector3d& boxMax, TriangleSoup& soup) {
  const double* d = c.data;
  const Eigen::Vector3d w(c.rotation[0], c.rotation[1], c.rotation[2]), centre(d[0], d[1], d[2]);
  const Eigen::Matrix3d turn = w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                                            : Eigen::Matrix3d::Identity();
  switch (c.type) {
    case QV_COLLIDER_PLANE: {
      const Eigen::Vector3d n = Eigen::Vector3d(d[0], d[1], d[2]).normalized();
      const double offset = d[3] / Eigen::Vector3d(d[0], d[1], d[2]).norm();
      const Eigen::Vector3d mid = 0.5 * (boxMin + boxMax), foot = mid - (n.dot(mid) - offset) * n;
      const double half = (boxMax - boxMin).norm();
      const Eigen::Vector3d u = half * n.unitOrthogonal(), v = n.cross(u);
      const unsigned a = addVertex(soup, foot - u - v), b = addVertex(soup, foot + u - v);
      addQuad(soup, a, b, addVertex(soup, foot + u + v), addVertex(soup, foot - u + v));
      break;
    }
    case QV_COLLIDER_SPHERE: addRoundShape(soup, {d[0], d[1], d[2]}, Eigen::Vector3d::UnitZ(), d[3], 0); break;
    case QV_COLLIDER_CAPSULE: {
      const Eigen::Vector3d p0(d[0], d[1], d[2]), p1(d[3], d[4], d[5]);
      const double length = (p1 - p0).norm();
      addRoundShape(soup, p0, length > 0 ? Eigen::Vector3d(p1 - p0) : Eigen::Vector3d::UnitZ(), d[6], length);
      break;
    }
    case QV_COLLIDER_BOX: {
      const Eigen::Vector3d half(d[3], d[4], d[5]);
      unsigned corner[8];
      for (int k = 0; k < 8; ++k)
        corner[k] = addVertex(soup, centre + turn * Eigen::Vector3d((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1)
                                                        .cwiseProduct(half));
      // Faces, counter-clockwise seen from outside: -x, +x, -y, +y, -z, +z.
      addQuad(soup, corner[0], corner[4], corner[6], corner[2]);
      addQuad(soup, corner[1], corner[3], corner[7], corner[5]);
      addQuad(soup, corner[0], corner[1], corner[5], corner[4]);
      addQuad(soup, corner[2], corner[6], corner[7], corner[3]);
      addQuad(soup, corner[0], corner[2], corner[3], corner[1]);
      addQuad(soup, corner[4], corner[5], corner[7], corner[6]);
      break;
    }
    case QV_COLLIDER_MESH: {
      if (!surface) break;
      const unsigned first = static_cast<unsigned>(soup.positions.size() / 3);
      for (size_t v = 0; v < surface->positions.size() / 3; ++v)
        addVertex(soup, centre + turn * Eigen::Vector3d(surface->positions[3 * v], surface->positions[3 * v + 1],
                                                        surface->positions[3 * v + 2]));
      for (int index : surface->triangles) soup.triangles.push_back(first + static_cast<unsigned>(index));
      break;
    }
  }
}

} // namespace quiver::app
