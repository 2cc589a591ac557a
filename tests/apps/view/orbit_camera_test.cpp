#include "apps/view/orbit_camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace quiver::app {
namespace {

// A point projected by the GL matrices (what the screen shows) lies on the ray cast back through
// that pixel (what picking uses): the two are computed independently.
TEST(OrbitCamera, RayThroughAProjectedPointPassesThroughIt) {
  OrbitCamera camera = OrbitCamera::framing(Eigen::Vector3d(0, -0.1, -0.2), Eigen::Vector3d(1, 0.1, 0.3), 16.0 / 9);
  camera.orbit(20, -10);
  const double width = 1280, height = 720;
  const Eigen::Matrix4f m = camera.projection(width / height) * camera.view();
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.5, 0, 0.05), Eigen::Vector3d(1, 0.1, 0.3), Eigen::Vector3d(0, -0.1, -0.2)}) {
    const Eigen::Vector4f clip = m * Eigen::Vector4f(float(p.x()), float(p.y()), float(p.z()), 1);
    const double ndcX = clip.x() / clip.w(), ndcY = clip.y() / clip.w();
    ASSERT_LT(std::abs(ndcX), 1.0) << "the framed box is in view";
    ASSERT_LT(std::abs(ndcY), 1.0);
    const Ray ray = camera.ray((ndcX + 1) / 2 * width, (1 - ndcY) / 2 * height, width, height);
    EXPECT_NEAR(ray.direction.norm(), 1, 1e-12);
    const Eigen::Vector3d toPoint = p - ray.origin;
    const double offRay = (toPoint - toPoint.dot(ray.direction) * ray.direction).norm();
    EXPECT_LT(offRay, 1e-5 * toPoint.norm()) << "float matrices: about 1e-6 relative";
    EXPECT_GT(toPoint.dot(ray.direction), 0) << "in front of the camera";
  }
}

TEST(OrbitCamera, OrbitNeverTurnsOverTheTopAndZoomStaysPositive) {
  OrbitCamera camera;
  camera.orbit(0, 500);
  EXPECT_EQ(camera.elevation, 89);
  camera.orbit(0, -1000);
  EXPECT_EQ(camera.elevation, -89);
  camera.zoom(0);
  EXPECT_GT(camera.distance, 0);
}

TEST(OrbitCamera, FramingKeepsTheWholeBoxInViewOfTallAndWideWindows) {
  const Eigen::Vector3d lo(-2, 0, 0), hi(3, 0.5, 0.25);
  for (const double aspect : {0.2, 1.0, 5.0}) {
    const OrbitCamera camera = OrbitCamera::framing(lo, hi, aspect);
    const Eigen::Matrix4f m = camera.projection(aspect) * camera.view();
    double widest = 0;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector4f p((corner & 1 ? hi : lo).x(), (corner & 2 ? hi : lo).y(), (corner & 4 ? hi : lo).z(), 1);
      const Eigen::Vector4f clip = m * p;
      EXPECT_LT(std::abs(clip.x() / clip.w()), 1) << "aspect " << aspect;
      EXPECT_LT(std::abs(clip.y() / clip.w()), 1) << "aspect " << aspect;
      EXPECT_LT(std::abs(clip.z() / clip.w()), 1) << "between the near and far planes";
      widest = std::max({widest, double(std::abs(clip.x() / clip.w())), double(std::abs(clip.y() / clip.w()))});
    }
    EXPECT_GT(widest, 0.3) << "and not lost in the middle; aspect " << aspect;
  }
}

} // namespace
} // namespace quiver::app
