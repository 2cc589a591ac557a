#include "apps/view/orbit_camera.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace quiver::app {

namespace {
constexpr double kDegree = M_PI / 180;
}

OrbitCamera OrbitCamera::framing(const Eigen::Vector3d& boxMin, const Eigen::Vector3d& boxMax, double aspect) {
  OrbitCamera c;
  c.target = 0.5 * (boxMin + boxMax);
  const double radius = std::max(0.5 * (boxMax - boxMin).norm(), 1e-9);
  // The bounding sphere fits the narrower of the two fields of view, with a margin for deformation.
  const double vertical = 0.5 * c.fieldOfView * kDegree, horizontal = std::atan(aspect * std::tan(vertical));
  c.distance = 1.3 * radius / std::sin(std::min(vertical, horizontal));
  return c;
}

Eigen::Vector3d OrbitCamera::eye() const {
  const double a = azimuth * kDegree, e = elevation * kDegree;
  return target + distance * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

Eigen::Matrix4f OrbitCamera::view() const {
  const Eigen::Vector3d back = (eye() - target).normalized();
  const Eigen::Vector3d right = Eigen::Vector3d::UnitZ().cross(back).normalized(), up = back.cross(right);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<1, 3>(0, 0) = right.transpose();
  m.block<1, 3>(1, 0) = up.transpose();
  m.block<1, 3>(2, 0) = back.transpose();
  m.block<3, 1>(0, 3) = -m.block<3, 3>(0, 0) * eye();
  return m.cast<float>();
}

Eigen::Matrix4f OrbitCamera::projection(double aspect) const {
  // Near and far planes scale with the distance so that depth precision follows the zoom.
  const double n = 0.01 * distance, f = 100 * distance, t = std::tan(0.5 * fieldOfView * kDegree);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = 1 / (aspect * t);
  p(1, 1) = 1 / t;
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2 * f * n / (f - n);
  p(3, 2) = -1;
  return p.cast<float>();
}

Ray OrbitCamera::ray(double x, double y, double width, double height) const {
  const Eigen::Matrix3d rotation = view().block<3, 3>(0, 0).cast<double>();  // rows: right, up, back
  const double t = std::tan(0.5 * fieldOfView * kDegree);
  const double ndcX = 2 * x / width - 1, ndcY = 1 - 2 * y / height;
  const Eigen::Vector3d local(ndcX * t * width / height, ndcY * t, -1);
  return {eye(), (rotation.transpose() * local).normalized()};
}

void OrbitCamera::orbit(double dAzimuth, double dElevation) {
  azimuth = std::fmod(azimuth + dAzimuth, 360.0);
  elevation = std::clamp(elevation + dElevation, -89.0, 89.0);  // never straight up: z stays "up" on screen
}

void OrbitCamera::zoom(double factor) { distance = std::max(distance * factor, 1e-9); }

} // namespace quiver::app
