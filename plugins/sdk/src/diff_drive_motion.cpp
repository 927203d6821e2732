#include "beaconloc/core/models/diff_drive_motion.hpp"

#include <cmath>

namespace beaconloc {

DiffDrivePrediction predict_diff_drive(const Pose2& pose, double wheel_velocity_right_mps,
                                       double wheel_velocity_left_mps, double wheel_base_m, double dt_s) {
  DiffDrivePrediction out = diff_drive_step(pose, wheel_velocity_right_mps, wheel_velocity_left_mps, wheel_base_m, dt_s);
  out.pose = {pose.x() + out.step.x(), pose.y() + out.step.y(), wrap_angle_rad(pose.z() + out.step.z())};
  return out;
}

DiffDrivePrediction diff_drive_step(const Pose2& pose, double wheel_velocity_right_mps, double wheel_velocity_left_mps,
                                    double wheel_base_m, double dt_s) {
  const double delta_d = dt_s * (wheel_velocity_right_mps + wheel_velocity_left_mps) / 2.0;
  const double delta_phi = dt_s * (wheel_velocity_right_mps - wheel_velocity_left_mps) / wheel_base_m;
  const double heading = pose.z() + delta_phi / 2.0;
  const double c = std::cos(heading), s = std::sin(heading);

  DiffDrivePrediction out;
  out.step = {delta_d * c, delta_d * s, delta_phi};
  out.pose = pose;

  out.jacobian_pose << 1.0, 0.0, -delta_d * s,  //
      0.0, 1.0, delta_d * c,                    //
      0.0, 0.0, 1.0;

  Eigen::Matrix<double, 3, 2> d_pose_d_increment;  // d f / d [Delta D, Delta phi]
  d_pose_d_increment << c, -delta_d / 2.0 * s,     //
      s, delta_d / 2.0 * c,                        //
      0.0, 1.0;
  Eigen::Matrix2d d_increment_d_wheels;            // d [Delta D, Delta phi] / d [v_R, v_L]
  d_increment_d_wheels << dt_s / 2.0, dt_s / 2.0,  //
      dt_s / wheel_base_m, -dt_s / wheel_base_m;
  out.jacobian_wheels = d_pose_d_increment * d_increment_d_wheels;
  return out;
}

}  // namespace beaconloc
