#include "beaconloc/core/models/velocity_motion.hpp"

#include <cmath>

namespace beaconloc {

VelocityStep velocity_step(const Pose2& pose, double v, double omega, double dt) {
  const double theta = pose.z();
  const double c0 = std::cos(theta), s0 = std::sin(theta);
  VelocityStep out;
  out.jacobian_pose.setIdentity();
  if (std::abs(omega) < 1e-9) {
    out.step << v * dt * c0, v * dt * s0, omega * dt;
    out.jacobian_pose(0, 2) = -v * dt * s0;
    out.jacobian_pose(1, 2) = v * dt * c0;
    out.jacobian_velocity << dt * c0, -v * dt * dt * s0 / 2.0,  //
        dt * s0, v * dt * dt * c0 / 2.0,                        //
        0.0, dt;
    return out;
  }
  const double r = v / omega;  // eq. 11
  const double c1 = std::cos(theta + omega * dt), s1 = std::sin(theta + omega * dt);
  out.step << -r * s0 + r * s1, r * c0 - r * c1, omega * dt;
  out.jacobian_pose(0, 2) = -r * c0 + r * c1;
  out.jacobian_pose(1, 2) = -r * s0 + r * s1;
  out.jacobian_velocity << (s1 - s0) / omega, v * (s0 - s1) / (omega * omega) + r * c1 * dt,  //
      (c0 - c1) / omega, v * (c1 - c0) / (omega * omega) + r * s1 * dt,                       //
      0.0, dt;
  return out;
}

Pose2 predict_velocity_motion(const Pose2& pose, double v, double omega, double dt) {
  const Pose2 step = velocity_step(pose, v, omega, dt).step;
  return {pose.x() + step.x(), pose.y() + step.y(), wrap_angle_rad(pose.z() + step.z())};
}

Eigen::Vector2d velocity_noise_variance(double v, double omega, const std::array<double, 4>& a) {
  return {a[0] * v * v + a[1] * omega * omega, a[2] * v * v + a[3] * omega * omega};  // eq. 6
}

}  // namespace beaconloc
