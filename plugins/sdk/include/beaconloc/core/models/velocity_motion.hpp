#pragma once
// The velocity motion model of seed 001 eq. 10-11 (Thrun et al.'s): the robot moves on an arc
// with translational velocity v and rotational velocity omega for dt; and the velocity noise
// of eq. 6, variances alpha_1 v^2 + alpha_2 omega^2 and alpha_3 v^2 + alpha_4 omega^2.
#include <array>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

// Eq. 10-11. |omega| below 1e-9 rad/s is the straight-line limit (ERRATA: omega -> 0 handled
// explicitly, where v / omega would divide by zero).
Pose2 predict_velocity_motion(const Pose2& pose, double v_mps, double omega_radps, double dt_s);

// Eq. 6: the diagonal of M, the variances of the noise on (v, omega).
Eigen::Vector2d velocity_noise_variance(double v_mps, double omega_radps, const std::array<double, 4>& alpha);

}  // namespace beaconloc
