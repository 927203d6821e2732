#include "beaconloc/core/odometry_timeline.hpp"

#include <algorithm>
#include <cmath>

#include "beaconloc/core/limits.hpp"

namespace beaconloc {

namespace {
// Symmetric, positive semi-definite (non-negative variances and determinant), and no variance
// beyond the square of the largest speed there is (a standard deviation over 10 m/s says nothing).
// A rank-one covariance (the replay's standing robot: noise on the turn rate only) has a
// determinant of exactly 0, which rounding (a fused multiply-add) can make a hair negative: a
// correlation beyond 1 by rounding only (1e-12 relative) is still accepted.
bool valid_covariance(const Eigen::Matrix2d& c) {
  const double max_variance = kMaxWheelSpeedMps * kMaxWheelSpeedMps;
  return c(0, 1) == c(1, 0) && c(0, 0) >= 0.0 && c(1, 1) >= 0.0 && c(0, 0) <= max_variance &&
         c(1, 1) <= max_variance && c(0, 0) * c(1, 1) - c(0, 1) * c(1, 0) >= -1e-12 * c(0, 0) * c(1, 1);
}
}  // namespace

InputResult check_odometry_numbers(const OdometrySample& o) {
  const bool finite = std::isfinite(o.wheel_velocity_right_mps) && std::isfinite(o.wheel_velocity_left_mps) &&
                      std::isfinite(o.wheel_base_m) && o.wheel_velocity_covariance.allFinite();
  if (!finite) return InputResult::rejected(Rejection::kNonFiniteOdometry);
  if (o.stamp_ns < 0) return InputResult::rejected(Rejection::kInvalidStamp);
  if (!(o.wheel_base_m > 0.0)) return InputResult::rejected(Rejection::kInvalidWheelBase);
  if (o.wheel_base_m > kMaxWheelBaseM) return InputResult::rejected(Rejection::kImplausibleWheelBase);
  if (std::abs(o.wheel_velocity_right_mps) > kMaxWheelSpeedMps ||
      std::abs(o.wheel_velocity_left_mps) > kMaxWheelSpeedMps) {
    // Integrated, 1e300 m/s puts the pose at 1e298 m; 1000 m/s jumps it 10 m a sample.
    return InputResult::rejected(Rejection::kImplausibleWheelSpeed);
  }
  if (!valid_covariance(o.wheel_velocity_covariance)) return InputResult::rejected(Rejection::kInvalidOdometryCovariance);
  return InputResult::ok();
}

OdometryTimeline::Step OdometryTimeline::advance(const OdometrySample& o) {
  Step step;
  step.result = check_odometry_numbers(o);
  if (!step.result.accepted) {
    return step;
  } else if (!last_stamp_ns_) {
    last_stamp_ns_ = o.stamp_ns;  // the anchor of the time line
  } else if (o.stamp_ns <= *last_stamp_ns_) {
    step.result =
        InputResult::rejected(o.stamp_ns == *last_stamp_ns_ ? Rejection::kDuplicateOdometry : Rejection::kOutOfOrderOdometry);
  } else {
    step.dt_s = ns_to_s(o.stamp_ns - *last_stamp_ns_);
    last_stamp_ns_ = o.stamp_ns;
    const double limit_s = gap_limit_s();  // the period as it stood before this interval
    intervals_s_[interval_count_ % kPeriodSamples] = step.dt_s;
    ++interval_count_;
    if (step.dt_s > limit_s) {
      // Integrating the velocities over the whole gap would invent motion: the sample
      // re-anchors the time line and the gap is reported.
      step.result = InputResult::rejected(Rejection::kOdometryGap);
    } else {
      step.integrate = true;
    }
  }
  return step;
}

double OdometryTimeline::gap_limit_s() const {
  if (interval_count_ < kMinPeriodSamples) return max_gap_s_;
  std::array<double, kPeriodSamples> sorted = intervals_s_;
  const std::size_t n = std::min(interval_count_, kPeriodSamples);
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.begin() + n);
  const double period_s = sorted[n / 2];
  return std::max(max_gap_s_, std::min(kGapPeriods * period_s, kMaxLearntGapS));
}

}  // namespace beaconloc
