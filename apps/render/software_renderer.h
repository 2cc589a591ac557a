#pragma once
// A small software rasterizer for headless pictures of deformed models (no display, no GPU):
// z-buffered triangles, two-sided Lambert shading with a fixed key light, and an orthographic
// camera that frames a bounding box. Enough for README figures and for tests that look at pixels.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace quiver::app {

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // row-major, top row first
  std::vector<float> depth;

  Image(int w, int h);
  void clear(const std::array<uint8_t, 3>& background);
  std::array<uint8_t, 3> pixel(int x, int y) const;
  // Copies `tile` into this image with its top-left corner at (x0, y0).
  void paste(const Image& tile, int x0, int y0);
};

struct Camera {
  Eigen::Matrix3d view;    // world -> camera rotation (rows: right, up, toward the viewer)
  Eigen::Vector3d centre;  // world point at the middle of the image
  double scale;            // pixels per world unit

  // Looks at the box from the direction (azimuth, elevation in degrees), fitting it with a margin.
  static Camera framing(const Eigen::Vector3d& boxMin, const Eigen::Vector3d& boxMax, int width, int height,
                        double azimuth = 35, double elevation = 25);
};

// Draws triangles (vertex indices into `positions`, 3 per vertex) in `colour`.
void drawTriangles(Image& image, const Camera& camera, const std::vector<float>& positions,
                   const std::vector<unsigned>& triangles, const std::array<uint8_t, 3>& colour);

// Writes `image` as an 8-bit RGB PNG, atomically. Throws std::runtime_error naming the path.
void writePng(const std::string& path, const Image& image);

} // namespace quiver::app
