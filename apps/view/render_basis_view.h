#pragma once
// Draws a render mesh deformed on the GPU, as an engine would: the render basis W U (3 rows of r
// floats per render vertex) in a texture buffer uploaded once, q and the body's frame as uniforms
// each frame, and in the vertex shader p = x + R (rest + sum_j q_j row_j - c) (docs/architecture.md,
// Render meshes). Shaded flat (the normals would need the tets' deformation gradients). Needs a
// current GL context for its whole life.
#include <vector>

#include <Eigen/Core>

namespace quiver::app {

class RenderBasisView {
public:
  // rest: 3 floats per vertex; rows: 3 x r floats per vertex (row 3i + c). Throws if a shader fails to build.
  RenderBasisView(const std::vector<float>& rest, const std::vector<unsigned>& triangles, const std::vector<float>& rows, int r);
  ~RenderBasisView();
  RenderBasisView(const RenderBasisView&) = delete;
  RenderBasisView& operator=(const RenderBasisView&) = delete;

  // One body: its q (r values) and the affine map of body coordinates (rest + u) to the world.
  void draw(const Eigen::Matrix4f& view, const Eigen::Matrix4f& projection, const Eigen::Vector3f& colour,
            const std::vector<double>& q, const Eigen::Matrix4f& bodyToWorld) const;

private:
  unsigned program_ = 0, array_ = 0, rest_ = 0, indices_ = 0, basisBuffer_ = 0, basisTexture_ = 0;
  int indexCount_ = 0, r_ = 0;
};

} // namespace quiver::app
