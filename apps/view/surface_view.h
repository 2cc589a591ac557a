#pragma once
// Draws a deforming triangle surface with OpenGL 3.3 core: positions and normals streamed each
// frame, two-sided Blinn-Phong lighting, flat or smooth (a headlight and a key light), plus flat-coloured lines for
// overlays such as the mouse spring. Needs a current GL context for its whole life.
#include <vector>

#include <Eigen/Core>

namespace quiver::app {

class SurfaceView {
public:
  SurfaceView(const std::vector<unsigned>& triangles, int vertexCount);  // throws if a shader fails to build
  ~SurfaceView();
  SurfaceView(const SurfaceView&) = delete;
  SurfaceView& operator=(const SurfaceView&) = delete;

  // Positions and normals: 3 floats per vertex each.
  void update(const std::vector<float>& positions, const std::vector<float>& normals);
  // `smoothNormals`: shade with the given vertex normals; otherwise each triangle flat.
  void draw(const Eigen::Matrix4f& view, const Eigen::Matrix4f& projection, const Eigen::Vector3f& colour,
            bool smoothNormals) const;
  // Line segments (pairs of points, 3 floats each) in one flat colour, drawn over the surface.
  void drawLines(const std::vector<float>& points, const Eigen::Matrix4f& view, const Eigen::Matrix4f& projection,
                 const Eigen::Vector3f& colour) const;

private:
  unsigned program_ = 0, surfaceArray_ = 0, lineArray_ = 0;
  unsigned positions_ = 0, normals_ = 0, indices_ = 0, linePoints_ = 0;
  int indexCount_ = 0;
};

} // namespace quiver::app
