#pragma once
// The checks every estimator makes of an odometry sample before integrating it, and the time
// line it keeps: finite values within the physical bounds of core/limits.hpp (wheel speeds and
// wheel base), a symmetric positive semi-definite covariance, non-negative stamps that move
// forward, and no integration across a gap (the velocities describe only the last period).
#include <optional>

#include "beaconloc/core/estimator.hpp"

namespace beaconloc {

// The checks of an odometry sample's numbers, wherever one is taken (the estimators' time line,
// the bridge's odom frame, a driver's odometry turned into wheel speeds): finite
// (non_finite_odometry), a stamp >= 0 (invalid_stamp), a wheel base in (0, kMaxWheelBaseM]
// (invalid_wheel_base, implausible_wheel_base), wheel speeds within kMaxWheelSpeedMps
// (implausible_wheel_speed), a symmetric positive semi-definite covariance with no variance beyond
// kMaxWheelSpeedMps^2 (invalid_odometry_covariance).
InputResult check_odometry_numbers(const OdometrySample& o);

class OdometryTimeline {
 public:
  explicit OdometryTimeline(double max_gap_s) : max_gap_s_(max_gap_s) {}

  struct Step {
    InputResult result;      // accepted, or the typed rejection
    double dt_s = 0.0;       // interval to integrate over; 0 for the first sample (the anchor)
    bool integrate = false;  // accepted and not the anchor
  };
  Step advance(const OdometrySample& o);
  std::optional<StampNs> last_stamp_ns() const { return last_stamp_ns_; }

 private:
  double max_gap_s_;
  std::optional<StampNs> last_stamp_ns_;
};

}  // namespace beaconloc
