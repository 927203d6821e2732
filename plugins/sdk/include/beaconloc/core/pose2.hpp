#pragma once
// Planar poses [x_m, y_m, yaw_rad] as Eigen::Vector3d, and SE(2) composition.
#include <Eigen/Core>
#include <cmath>

namespace beaconloc {

using Pose2 = Eigen::Vector3d;  // [x_m, y_m, yaw_rad]
using Cov3 = Eigen::Matrix3d;   // covariance over (x_m, y_m, yaw_rad)

// The angle in (-pi, pi]: an angle already there as it is, bit for bit; another the exact IEEE
// remainder by 2 pi (std::remainder rounds nothing), -pi taken to pi. NaN for a non-finite angle.
// (Was atan2(sin a, cos a): two to three times the cost, the dearest step of a UKF's sigma
// points, and a last-bit error even on angles needing no wrap.)
inline double wrap_angle_rad(double a) {
  if (a > -M_PI && a <= M_PI) return a;
  const double w = std::remainder(a, 2.0 * M_PI);
  return w <= -M_PI ? w + 2.0 * M_PI : w;
}

// Point given in the frame of `pose` expressed in the parent frame.
inline Eigen::Vector2d transform_point(const Pose2& pose, const Eigen::Vector2d& p) {
  const double c = std::cos(pose.z()), s = std::sin(pose.z());
  return {pose.x() + c * p.x() - s * p.y(), pose.y() + s * p.x() + c * p.y()};
}

// a (+) b: b given in the frame of a.
inline Pose2 compose(const Pose2& a, const Pose2& b) {
  const Eigen::Vector2d t = transform_point(a, b.head<2>());
  return {t.x(), t.y(), wrap_angle_rad(a.z() + b.z())};
}

// The pose of b expressed in the frame of a: (-a) (+) b.
inline Pose2 between(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.z()), s = std::sin(a.z());
  const Eigen::Vector2d d = b.head<2>() - a.head<2>();
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y(), wrap_angle_rad(b.z() - a.z())};
}

// a - b with the heading difference wrapped to (-pi, pi]: an innovation or a numeric derivative
// of poses.
inline Pose2 pose_difference(const Pose2& a, const Pose2& b) {
  return {a.x() - b.x(), a.y() - b.y(), wrap_angle_rad(a.z() - b.z())};
}

}  // namespace beaconloc
