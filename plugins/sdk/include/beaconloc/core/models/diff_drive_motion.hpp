#pragma once
// Differential-drive odometry motion model, seed 000 eq. 14 with its Jacobians eq. 16.
#include <Eigen/Core>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

struct DiffDrivePrediction {
  Pose2 pose;                                   // x_bar_k of eq. 14
  Eigen::Matrix3d jacobian_pose;                // J_f,x of eq. 16
  Eigen::Matrix<double, 3, 2> jacobian_wheels;  // J_f,u of eq. 16, u = [v_R, v_L]
};

// Eq. 14: Delta D = dT (v_R + v_L) / 2, Delta phi = dT (v_R - v_L) / B_w, the pose advanced along
// the mean heading phi + Delta phi / 2.
// J_f,u is the product printed in eq. 16, d f / d[Delta D, Delta phi] times
// d[Delta D, Delta phi] / d[v_R, v_L] = [[dT/2, dT/2], [dT/B_w, -dT/B_w]] (ERRATA: the copy
// prints the second factor with "R").
DiffDrivePrediction predict_diff_drive(const Pose2& pose, double wheel_velocity_right_mps,
                                       double wheel_velocity_left_mps, double wheel_base_m, double dt_s);

}  // namespace beaconloc
