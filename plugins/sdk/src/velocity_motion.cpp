#include "beaconloc/core/models/velocity_motion.hpp"

#include <cmath>

namespace beaconloc {

Pose2 predict_velocity_motion(const Pose2& pose, double v, double omega, double dt) {
  const double theta = pose.z();
  Pose2 out;
  if (std::abs(omega) < 1e-9) {
    out << pose.x() + v * dt * std::cos(theta), pose.y() + v * dt * std::sin(theta), theta;
  } else {
    const double r = v / omega;  // eq. 11
    out << pose.x() - r * std::sin(theta) + r * std::sin(theta + omega * dt),
        pose.y() + r * std::cos(theta) - r * std::cos(theta + omega * dt), theta + omega * dt;
  }
  out.z() = wrap_angle_rad(out.z());
  return out;
}

Eigen::Vector2d velocity_noise_variance(double v, double omega, const std::array<double, 4>& a) {
  return {a[0] * v * v + a[1] * omega * omega, a[2] * v * v + a[3] * omega * omega};  // eq. 6
}

}  // namespace beaconloc
