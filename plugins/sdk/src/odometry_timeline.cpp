#include "beaconloc/core/odometry_timeline.hpp"

#include <cmath>

namespace beaconloc {

OdometryTimeline::Step OdometryTimeline::advance(const OdometrySample& o) {
  Step step;
  const bool finite = std::isfinite(o.wheel_velocity_right_mps) && std::isfinite(o.wheel_velocity_left_mps) &&
                      std::isfinite(o.wheel_base_m) && o.wheel_velocity_covariance.allFinite();
  if (!finite) {
    step.result = InputResult::rejected("non_finite_odometry");
  } else if (!(o.wheel_base_m > 0.0)) {
    step.result = InputResult::rejected("invalid_wheel_base");
  } else if ((o.wheel_velocity_covariance.diagonal().array() < 0.0).any()) {
    step.result = InputResult::rejected("invalid_odometry_covariance");
  } else if (!last_stamp_ns_) {
    last_stamp_ns_ = o.stamp_ns;  // the anchor of the time line
  } else if (o.stamp_ns <= *last_stamp_ns_) {
    step.result =
        InputResult::rejected(o.stamp_ns == *last_stamp_ns_ ? "duplicate_odometry" : "out_of_order_odometry");
  } else {
    step.dt_s = ns_to_s(o.stamp_ns - *last_stamp_ns_);
    last_stamp_ns_ = o.stamp_ns;
    if (step.dt_s > max_gap_s_) {
      // Integrating the velocities over the whole gap would invent motion: the sample
      // re-anchors the time line and the gap is reported.
      step.result = InputResult::rejected("odometry_gap");
    } else {
      step.integrate = true;
    }
  }
  return step;
}

}  // namespace beaconloc
