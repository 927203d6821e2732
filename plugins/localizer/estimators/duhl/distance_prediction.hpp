#pragma once
// Dynamic distance estimation of seed 000, Section IV: the three distances q^i from a Tx to the
// receivers, predicted from odometry (eq. 23) with their covariance (eq. 24), corrected by a
// measurement (eq. 25-27), initialized from the robot pose (eq. 28-29).
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc::duhl {

using Distances = Eigen::Vector3d;    // q^i = [q_1, q_2, q_3] (m)
using DistanceCov = Eigen::Matrix3d;  // Q^i

struct ReceiverRing {
  double radius_m = 0.19;                 // r_R, receivers at 0, 120, 240 degrees (eq. 1)
  double height_m = 0.0;                  // the receivers' plane
  Eigen::Vector2d receiver(int l) const;  // ^L R_l
};

// The Tx as seen from the robot centre, from the three distances alone: the planar distance
// r = sqrt(rho^2 - z^2) with rho from the isotropic array (eq. 11), and the bearing theta
// relative to the robot's heading, from the identities checked in ERRATA (eq. 4):
//   2 q_1^2 - q_2^2 - q_3^2 = -6 r_R r cos(theta),   q_3^2 - q_2^2 = 2 sqrt(3) r_R r sin(theta).
struct TxGeometry {
  double planar_range_m;  // sqrt((rho^i)^2 - z_T^2)
  double bearing_rad;     // theta^i
};
TxGeometry tx_geometry(const Distances& q, double tx_height_above_receivers_m, const ReceiverRing& ring);

struct DistancePrediction {
  Distances q;                                  // q_bar_k (eq. 23)
  Eigen::Matrix3d jacobian_q;                   // J_g,q (eq. 24)
  Eigen::Matrix<double, 3, 2> jacobian_wheels;  // J_g,u, u = [v_R, v_L] (eq. 24)
};

// Eq. 23: q_bar = q + (alpha - beta) / q, with Delta D and Delta phi from the wheel velocities
// (eq. 14). rho and theta enter through the distances themselves (tx_geometry), so eq. 24's chain
// d beta / d q = [d beta / d rho, d beta / d theta] d(rho, theta) / d(x, y, phi) d(x, y, phi) / d q
// is taken as d beta / d(r, theta) d(r, theta) / d q.
DistancePrediction predict_distances(const Distances& q, double tx_height_above_receivers_m,
                                     double wheel_velocity_right_mps, double wheel_velocity_left_mps,
                                     double wheel_base_m, double dt_s, const ReceiverRing& ring);

// Eq. 28-29: the distances expected from the robot pose, and their covariance J P J^T.
struct DistanceInit {
  Distances q;
  DistanceCov covariance;
  Eigen::Matrix3d jacobian_pose;  // J_q,x
};
DistanceInit initial_distances(const Pose2& pose, const Cov3& pose_covariance,
                               const Eigen::Vector3d& tx_map_m, const ReceiverRing& ring);

// Not in the paper: whether a pose explains the distances it was computed from (an echo makes
// one Tx's distances contradict the others'): every distance within gate_sigma of the one the
// pose predicts (eq. 28), in sigmas of the distance's variance plus the prediction's (eq. 29).
inline constexpr double kDefaultResidualGateSigma = 4.0;
struct TxBelief {
  Eigen::Vector3d tx_map_m;
  Distances q;
  DistanceCov covariance;
};
bool explains_distances(const std::vector<TxBelief>& txs, const Pose2& pose, const Cov3& pose_covariance,
                        const ReceiverRing& ring, double gate_sigma);

// The triangle inequality between each two receivers and a Tx (ranges_of_one_firing_agree):
// false when an echo made one distance too long (or a distance is not finite).
bool possible_distances(const Distances& d, double variance_m2, const ReceiverRing& ring);

}  // namespace beaconloc::duhl
