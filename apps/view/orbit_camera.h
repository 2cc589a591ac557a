#pragma once
// A perspective camera orbiting a point, z up: what the viewer looks through, and how a cursor
// position becomes a ray into the scene (for picking and dragging).
#include <Eigen/Core>

namespace quiver::app {

struct Ray {
  Eigen::Vector3d origin, direction;  // direction has unit length
};

struct OrbitCamera {
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double distance = 1;
  double azimuth = 35, elevation = 25;  // degrees; the eye sits at (azimuth, elevation) around the target
  double fieldOfView = 40;              // vertical, degrees

  // Frames a box: looks at its centre from far enough that the whole box is in view of a window
  // `aspect` (width / height) wide.
  static OrbitCamera framing(const Eigen::Vector3d& boxMin, const Eigen::Vector3d& boxMax, double aspect);

  Eigen::Vector3d eye() const;
  Eigen::Matrix4f view() const;
  Eigen::Matrix4f projection(double aspect) const;  // width / height
  // The ray through a window point (pixels from the top-left corner of a width x height window).
  Ray ray(double x, double y, double width, double height) const;

  void orbit(double dAzimuth, double dElevation);
  void zoom(double factor);  // distance *= factor
};

} // namespace quiver::app
