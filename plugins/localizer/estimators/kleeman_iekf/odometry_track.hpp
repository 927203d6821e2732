#pragma once
// The dead reckoning seed 002 feeds its filter (Sec. 3.8): the robot's speed and turn rate from
// the wheel odometry, held piecewise constant over each odometry interval, integrated over any
// span of time: a beacon slot's heading increment (the input of eq. 24) and mean speed (the
// measurement of eq. 25), and the motion between two instants (the start-up fit, and the pose
// between two slots). Times are seconds from the estimator's epoch.
#include <deque>

#include "beaconloc/core/measurements.hpp"

namespace beaconloc::kleeman {

struct OdometryInterval {
  double start_s = 0.0;
  double end_s = 0.0;
  double speed_mps = 0.0;
  double turn_rate_radps = 0.0;
  double speed_variance_m2ps2 = 0.0;      // (m/s)^2, of this interval's speed
  double turn_rate_variance_rad2ps2 = 0.0;  // (rad/s)^2
};

// What the robot did between two instants.
struct DeadReckoning {
  double distance_m = 0.0;
  double dtheta_rad = 0.0;
  double distance_variance_m2 = 0.0;  // m^2: the intervals' speed noise, independent between intervals
  double dtheta_variance_rad2 = 0.0;    // rad^2
  // Displacement in the robot's frame at the span's start (x ahead, y to the left).
  double forward_m = 0.0;
  double left_m = 0.0;
  // Part of the span past the newest odometry, extrapolated with its velocities.
  double extrapolated_s = 0.0;
};

class OdometryTrack {
 public:
  // The sample's velocities over (end_s - dt_s, end_s] (core/measurements.hpp: OdometrySample).
  void add(const OdometrySample& o, double end_s, double dt_s);
  bool empty() const { return intervals_.empty(); }
  double newest_s() const { return intervals_.empty() ? 0.0 : intervals_.back().end_s; }
  // Integrated over [from_s, to_s] (from_s <= to_s): the intervals that cover it; a stretch before
  // the oldest interval or in a gap counts as standing still, one past the newest holds its
  // velocities (and is reported as extrapolated).
  DeadReckoning between(double from_s, double to_s) const;
  // Drops the intervals that end before s.
  void forget_before(double s);

 private:
  std::deque<OdometryInterval> intervals_;
};

}  // namespace beaconloc::kleeman
