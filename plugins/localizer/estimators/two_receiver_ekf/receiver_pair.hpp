#pragma once
// Seed 004's geometry of the two receivers: the robot's pose from the positions of its front and
// rear receivers (eq. 11) with its covariance (eq. 12), and how wheel odometry moves a receiver
// (eq. 3: the receivers' state equation follows from the robot's, eq. 2).
#include <Eigen/Core>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

// Where the two receivers sit on the robot (its base frame); they must differ.
struct ReceiverPair {
  Eigen::Vector2d front_base_m;
  Eigen::Vector2d rear_base_m;
  double separation_m() const { return (front_base_m - rear_base_m).norm(); }
};

struct PairPose {
  Pose2 pose_map_base = Pose2::Zero();
  Cov3 covariance = Cov3::Identity();
};

// Eq. 11: the heading is the direction from the rear receiver to the front one (less that
// direction on the robot), and the centre is where the receivers' mounting puts it:
// t = (P_f + P_r) / 2 - R(yaw) (b_f + b_r) / 2, which is eq. 11's midpoint for the paper's
// receivers at (l, 0) and (-l, 0).
// Eq. 12 (its printed form is lost in the copy; derived here for any mounting): with the two
// estimates independent, Sigma = J_f V_f J_f^T + J_r V_r J_r^T, J the Jacobian of (t, yaw) in
// each receiver's position. For the paper's mounting and V_f = V_r = V it is the position
// covariance V / 2 and a heading variance n^T V n / (2 l^2), n the unit normal to the robot's
// axis: the heading error shrinks as the receivers' separation 2 l grows (Sec. 3, Sec. 5).
PairPose pose_from_receivers(const Eigen::Vector2d& front_map_m, const Eigen::Matrix2d& front_covariance,
                             const Eigen::Vector2d& rear_map_m, const Eigen::Matrix2d& rear_covariance,
                             const ReceiverPair& pair);

// How a receiver mounted at receiver_base_m moves while the robot at pose_map_base (heading
// variance yaw_variance_rad2) drives its wheels at (v_R, v_L) for dt_s (eq. 2, seed 000's eq. 14
// for this differential robot): the receiver's displacement in the map and its covariance, from
// the wheel velocities' covariance and the heading's uncertainty.
struct ReceiverStep {
  Eigen::Vector2d displacement_m = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};
ReceiverStep receiver_step(const Pose2& pose_map_base, double yaw_variance_rad2,
                           const Eigen::Vector2d& receiver_base_m, double wheel_velocity_right_mps,
                           double wheel_velocity_left_mps, const Eigen::Matrix2d& wheel_velocity_covariance,
                           double wheel_base_m, double dt_s);

}  // namespace beaconloc
