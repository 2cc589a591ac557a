#pragma once
// The tools' colliders: --collider values parsed into the runtime's qv_collider array, with the
// triangle meshes of mesh colliders read from their files and kept alive as long as the set.
#include <memory>
#include <string>
#include <vector>

#include "formats/mesh/read_surface.h"
#include "quiver/quiver.h"

namespace quiver::app {

class ColliderSet {
public:
  // A --collider value: plane:nx,ny,nz,d (points with n.x = d), sphere:x,y,z,radius,
  // box:cx,cy,cz,hx,hy,hz (axis-aligned), capsule:x0,y0,z0,x1,y1,z1,radius, or mesh:FILE[,x,y,z]
  // (a closed surface, moved by x,y,z); throws naming the value and what is wrong.
  void add(const std::string& text, double friction, double restitution);
  const qv_collider* data() const { return colliders_.data(); }
  int size() const { return static_cast<int>(colliders_.size()); }
  const qv_collider& operator[](int k) const { return colliders_[static_cast<size_t>(k)]; }
  // A mesh collider's surface as read (null for the other types).
  const SurfaceMesh* surface(int k) const { return surfaces_[static_cast<size_t>(k)].get(); }

private:
  struct MeshRelease {
    void operator()(qv_triangle_mesh* mesh) const { qv_triangle_mesh_destroy(mesh); }
  };
  std::vector<qv_collider> colliders_;
  std::vector<std::unique_ptr<SurfaceMesh>> surfaces_;
  std::vector<std::unique_ptr<qv_triangle_mesh, MeshRelease>> meshes_;
};

} // namespace quiver::app
