#include "receiver_pair.hpp"

#include <cmath>

#include "beaconloc/core/models/diff_drive_motion.hpp"

namespace beaconloc {

namespace {
Eigen::Matrix2d rotation(double yaw_rad) {
  Eigen::Matrix2d r;
  r << std::cos(yaw_rad), -std::sin(yaw_rad), std::sin(yaw_rad), std::cos(yaw_rad);
  return r;
}
// d R(yaw) / d yaw.
Eigen::Matrix2d rotation_derivative(double yaw_rad) {
  Eigen::Matrix2d r;
  r << -std::sin(yaw_rad), -std::cos(yaw_rad), std::cos(yaw_rad), -std::sin(yaw_rad);
  return r;
}
}  // namespace

PairPose pose_from_receivers(const Eigen::Vector2d& front_map_m, const Eigen::Matrix2d& front_covariance,
                             const Eigen::Vector2d& rear_map_m, const Eigen::Matrix2d& rear_covariance,
                             const ReceiverPair& pair) {
  const Eigen::Vector2d d_map = front_map_m - rear_map_m;
  const Eigen::Vector2d d_base = pair.front_base_m - pair.rear_base_m;
  const double yaw = wrap_angle_rad(std::atan2(d_map.y(), d_map.x()) - std::atan2(d_base.y(), d_base.x()));
  const Eigen::Vector2d centre_base = (pair.front_base_m + pair.rear_base_m) / 2.0;
  PairPose out;
  out.pose_map_base.head<2>() = (front_map_m + rear_map_m) / 2.0 - rotation(yaw) * centre_base;
  out.pose_map_base.z() = yaw;
  // d yaw / d P_f = [-d_y, d_x] / |d|^2 = -d yaw / d P_r.
  const double d2 = std::max(d_map.squaredNorm(), 1e-12);
  const Eigen::RowVector2d dyaw_dfront(-d_map.y() / d2, d_map.x() / d2);
  const Eigen::Vector2d dt_dyaw = -rotation_derivative(yaw) * centre_base;
  Eigen::Matrix<double, 3, 2> j_front, j_rear;
  j_front.topRows<2>() = 0.5 * Eigen::Matrix2d::Identity() + dt_dyaw * dyaw_dfront;
  j_front.row(2) = dyaw_dfront;
  j_rear.topRows<2>() = 0.5 * Eigen::Matrix2d::Identity() - dt_dyaw * dyaw_dfront;
  j_rear.row(2) = -dyaw_dfront;
  out.covariance = j_front * front_covariance * j_front.transpose() + j_rear * rear_covariance * j_rear.transpose();
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose()).eval();
  return out;
}

ReceiverStep receiver_step(const Pose2& pose, double yaw_variance_rad2, const Eigen::Vector2d& receiver_base_m,
                           double right_mps, double left_mps, const Eigen::Matrix2d& wheel_covariance,
                           double wheel_base_m, double dt_s) {
  const DiffDrivePrediction p = diff_drive_step(pose, right_mps, left_mps, wheel_base_m, dt_s);
  const double yaw0 = pose.z();
  const double yaw1 = yaw0 + p.step.z();
  ReceiverStep out;
  // r = t + R(yaw) b: the step of the centre plus the turn of the lever arm.
  out.displacement_m = p.step.head<2>() + (rotation(yaw1) - rotation(yaw0)) * receiver_base_m;
  // In the wheel velocities: the centre's step (eq. 16's J_f,u) and the lever arm turned by the
  // heading's step.
  const Eigen::Matrix<double, 2, 2> d_wheels =
      p.jacobian_wheels.topRows<2>() + rotation_derivative(yaw1) * receiver_base_m * p.jacobian_wheels.row(2);
  // In the heading: the centre's step turns with it (eq. 16's J_f,x, third column) and so does
  // the lever arm's.
  const Eigen::Vector2d d_yaw =
      p.jacobian_pose.block<2, 1>(0, 2) + (rotation_derivative(yaw1) - rotation_derivative(yaw0)) * receiver_base_m;
  out.covariance = d_wheels * wheel_covariance * d_wheels.transpose() + yaw_variance_rad2 * d_yaw * d_yaw.transpose();
  return out;
}

}  // namespace beaconloc
