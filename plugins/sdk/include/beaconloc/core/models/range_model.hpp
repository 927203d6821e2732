#pragma once
// Range measurement model: 3D distance from a receiver on the robot to a ceiling beacon
// (seed 000 eq. 2-3, general beacon height). Shared by every filter (EKF, IEKF, UKF, H-infinity)
// and by the range-only pose solver.
#include <Eigen/Core>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

struct RangePrediction {
  double range_m = 0.0;
  Eigen::RowVector3d jacobian_pose = Eigen::RowVector3d::Zero();  // d range / d [x, y, yaw]
};

// receiver_base_m: the receiver in the frame of `pose` (seed 000 eq. 1), at height receiver_z_m.
RangePrediction predict_range(const Pose2& pose, const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                              const Eigen::Vector3d& beacon_map_m);

}  // namespace beaconloc
