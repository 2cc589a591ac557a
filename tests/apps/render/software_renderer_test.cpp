// The headless rasterizer against geometry worked out by hand: covered area, depth order, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "apps/render/software_renderer.h"

namespace quiver::app {
namespace {

constexpr std::array<uint8_t, 3> kBlack{0, 0, 0}, kRed{255, 0, 0}, kGreen{0, 255, 0};

// Screen x = 50 + 40 X, y = 50 - 40 Y on a 100 x 100 image; camera z points at the viewer.
Camera straightOn() { return Camera{Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 40.0}; }

// Shading scales the colour, so a pixel counts as `colour` when it is lit in the same channels and dark in the others.
int countPixels(const Image& image, const std::array<uint8_t, 3>& colour) {
  int n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::array<uint8_t, 3> p = image.pixel(x, y);
      bool same = true;
      for (int c = 0; c < 3; ++c) same = same && ((p[c] > 0) == (colour[c] > 0));
      n += same;
    }
  return n;
}

TEST(SoftwareRenderer, CoversTheTrianglesAreaInPixels) {
  Image image(100, 100);
  image.clear(kBlack);
  // A right triangle of legs 1 -> 40 px: 800 px^2. Pixel-centre sampling errs by at most about half the perimeter.
  drawTriangles(image, straightOn(), {0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}, kRed);
  const int covered = image.width * image.height - countPixels(image, kBlack);
  EXPECT_NEAR(covered, 800, 0.5 * (40 + 40 + 40 * std::sqrt(2.0)));
  // Inside and outside, away from the edges.
  EXPECT_NE(image.pixel(55, 45), kBlack);
  EXPECT_EQ(image.pixel(45, 45), kBlack);
  EXPECT_EQ(image.pixel(80, 20), kBlack);
}

TEST(SoftwareRenderer, TheNearerSurfaceWinsWhicheverIsDrawnFirst) {
  // Two unit squares over the same pixels, at z = 0 and z = 0.5 (nearer).
  const std::vector<float> squares = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 0.5f, 1, 0, 0.5f, 1, 1, 0.5f, 0, 1, 0.5f};
  const std::vector<unsigned> far = {0, 1, 2, 0, 2, 3}, near = {4, 5, 6, 4, 6, 7};
  for (bool nearFirst : {false, true}) {
    Image image(100, 100);
    image.clear(kBlack);
    drawTriangles(image, straightOn(), squares, nearFirst ? near : far, nearFirst ? kGreen : kRed);
    drawTriangles(image, straightOn(), squares, nearFirst ? far : near, nearFirst ? kRed : kGreen);
    EXPECT_EQ(countPixels(image, kRed), 0) << "near first: " << nearFirst;
    EXPECT_NEAR(countPixels(image, kGreen), 1600, 80) << "near first: " << nearFirst;
  }
}

TEST(SoftwareRenderer, NonFiniteOrFarAwayPositionsDrawNothing) {
  Image image(100, 100);
  image.clear(kBlack);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  drawTriangles(image, straightOn(), {0, 0, 0, 1, 0, 0, nan, 1, 0, 0, 0, 0, 1e30f, 0, 0, 0, 1, 0}, {0, 1, 2, 3, 4, 5},
                kRed);
  EXPECT_EQ(countPixels(image, kBlack), 100 * 100);
}

} // namespace
} // namespace quiver::app
