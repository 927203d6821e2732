#pragma once
// An odometry sample of a robot standing still (both wheels at 0 m/s), stamped stamp_ns: what a
// test pushes to move an estimator's time line without moving its pose.
#include <Eigen/Core>

#include "beaconloc/core/measurements.hpp"

namespace beaconloc {

inline OdometrySample standing_odometry(StampNs stamp_ns, double wheel_base_m = 0.4,
                                        double wheel_velocity_variance_m2ps2 = 1e-4) {
  OdometrySample o;
  o.stamp_ns = stamp_ns;
  o.wheel_base_m = wheel_base_m;
  o.wheel_velocity_covariance = wheel_velocity_variance_m2ps2 * Eigen::Matrix2d::Identity();
  return o;
}

}  // namespace beaconloc
