#include "apps/render/software_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>
#include <png.h>

#include "formats/atomic_file.h"

namespace quiver::app {

Image::Image(int w, int h) : width(w), height(h), rgb(3 * static_cast<size_t>(w) * h), depth(static_cast<size_t>(w) * h) {}

void Image::clear(const std::array<uint8_t, 3>& background) {
  for (size_t i = 0; i < depth.size(); ++i) {
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = background[c];
    depth[i] = -std::numeric_limits<float>::infinity();
  }
}

std::array<uint8_t, 3> Image::pixel(int x, int y) const {
  const size_t i = 3 * (static_cast<size_t>(y) * width + x);
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

void Image::paste(const Image& tile, int x0, int y0) {
  for (int y = 0; y < tile.height && y0 + y < height; ++y)
    for (int x = 0; x < tile.width && x0 + x < width; ++x)
      for (int c = 0; c < 3; ++c)
        rgb[3 * (static_cast<size_t>(y0 + y) * width + x0 + x) + c] = tile.rgb[3 * (static_cast<size_t>(y) * tile.width + x) + c];
}

Camera Camera::framing(const Eigen::Vector3d& boxMin, const Eigen::Vector3d& boxMax, int width, int height,
                       double azimuth, double elevation) {
  const double a = azimuth * M_PI / 180, e = elevation * M_PI / 180;
  // z up in the world; the viewer sits at (azimuth, elevation) around the box.
  const Eigen::Vector3d toward(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
  const Eigen::Vector3d right = Eigen::Vector3d::UnitZ().cross(toward).normalized();
  const Eigen::Vector3d up = toward.cross(right);
  Camera c;
  c.view.row(0) = right;
  c.view.row(1) = up;
  c.view.row(2) = toward;
  c.centre = 0.5 * (boxMin + boxMax);
  double halfWidth = 0, halfHeight = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1 ? boxMax : boxMin).x(), (corner & 2 ? boxMax : boxMin).y(),
                            (corner & 4 ? boxMax : boxMin).z());
    const Eigen::Vector3d q = c.view * (p - c.centre);
    halfWidth = std::max(halfWidth, std::abs(q.x()));
    halfHeight = std::max(halfHeight, std::abs(q.y()));
  }
  c.scale = 0.9 * std::min(width / (2 * std::max(halfWidth, 1e-12)), height / (2 * std::max(halfHeight, 1e-12)));
  return c;
}

void drawTriangles(Image& image, const Camera& camera, const std::vector<float>& positions,
                   const std::vector<unsigned>& triangles, const std::array<uint8_t, 3>& colour) {
  const Eigen::Vector3d light = Eigen::Vector3d(0.3, 0.5, 1.0).normalized();  // in camera space
  for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
    Eigen::Vector3d p[3];
    for (int k = 0; k < 3; ++k) {
      const float* x = &positions[3 * static_cast<size_t>(triangles[t + k])];
      const Eigen::Vector3d q = camera.view * (Eigen::Vector3d(x[0], x[1], x[2]) - camera.centre);
      // Depth in pixels too, so that the shading normal below weighs all three axes alike.
      p[k] = Eigen::Vector3d(image.width / 2.0 + camera.scale * q.x(), image.height / 2.0 - camera.scale * q.y(),
                             camera.scale * q.z());
    }
    // A diverged simulation gives huge or NaN positions; casting those to int below would be undefined.
    const auto onCanvas = [&](const Eigen::Vector3d& v) {
      return v.allFinite() && std::abs(v.x()) < 1e6 && std::abs(v.y()) < 1e6;
    };
    if (!onCanvas(p[0]) || !onCanvas(p[1]) || !onCanvas(p[2])) continue;
    // Shade by the camera-space normal (both sides lit, so open or inverted surfaces still show).
    Eigen::Vector3d e1(p[1].x() - p[0].x(), -(p[1].y() - p[0].y()), p[1].z() - p[0].z());
    Eigen::Vector3d e2(p[2].x() - p[0].x(), -(p[2].y() - p[0].y()), p[2].z() - p[0].z());
    Eigen::Vector3d normal = e1.cross(e2);
    if (normal.norm() == 0) continue;
    normal.normalize();
    const double shade = 0.25 + 0.75 * std::abs(normal.dot(light));
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].x(), p[1].x(), p[2].x()}))));
    const int x1 = std::min(image.width - 1, static_cast<int>(std::ceil(std::max({p[0].x(), p[1].x(), p[2].x()}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].y(), p[1].y(), p[2].y()}))));
    const int y1 = std::min(image.height - 1, static_cast<int>(std::ceil(std::max({p[0].y(), p[1].y(), p[2].y()}))));
    const double area = (p[1].x() - p[0].x()) * (p[2].y() - p[0].y()) - (p[2].x() - p[0].x()) * (p[1].y() - p[0].y());
    if (std::abs(area) < 1e-12) continue;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double w0 = ((p[1].x() - px) * (p[2].y() - py) - (p[2].x() - px) * (p[1].y() - py)) / area;
        const double w1 = ((p[2].x() - px) * (p[0].y() - py) - (p[0].x() - px) * (p[2].y() - py)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const float z = static_cast<float>(w0 * p[0].z() + w1 * p[1].z() + w2 * p[2].z());
        const size_t i = static_cast<size_t>(y) * image.width + x;
        if (z <= image.depth[i]) continue;
        image.depth[i] = z;
        for (int c = 0; c < 3; ++c) image.rgb[3 * i + c] = static_cast<uint8_t>(std::lround(colour[c] * shade));
      }
  }
}

void writePng(const std::string& path, const Image& image) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) throw std::runtime_error(path + ": cannot start a PNG encoder");
  std::string bytes;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(path + ": PNG encoding failed");
  }
  png_set_write_fn(
      png, &bytes,
      [](png_structp p, png_bytep data, png_size_t size) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), size);
      },
      nullptr);
  png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(&image.rgb[3 * static_cast<size_t>(y) * image.width]));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  writeFileAtomically(path, bytes);
}

} // namespace quiver::app
