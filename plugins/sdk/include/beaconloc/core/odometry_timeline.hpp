#pragma once
// The checks every estimator makes of an odometry sample before integrating it, and the time
// line it keeps: finite values within the physical bounds of core/limits.hpp (wheel speeds and
// wheel base), a symmetric positive semi-definite covariance, non-negative stamps that move
// forward, and no integration across a gap (the velocities describe only the last period).
#include <array>
#include <cstddef>
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

// The estimators' default max_odometry_gap_s (s): at 100 Hz, 19 samples missing in a row.
inline constexpr double kDefaultMaxOdometryGapS = 0.2;

// A gap is an interval between two samples longer than max_gap_s or, for a sensor slower than
// 20 Hz (where kGapPeriods of its period exceed the default), longer than kGapPeriods of its own
// period: the median of its last (up to kPeriodSamples) intervals, once it has
// kMinPeriodSamples. Up to three samples lost in a row are then no gap: the velocities are held
// over them as over one period. The CMU mower's odometry comes at 5 Hz (every 0.17-0.23 s) on
// Plaza 1, and at 10 Hz on Plaza 2, where one row reports 1.24 m driven over 0.35 s: under a
// fixed 0.2 s limit both lost motion (half of Plaza 1's samples and that row were refused as
// gaps). max_gap_s is the floor: the learnt limit only ever relaxes it, and never beyond
// kMaxLearntGapS, past which velocities held constant invent motion (up to 10 m at the fastest
// wheel speed there is). The median takes in the gaps too, so that a sensor that turns slower
// is learnt: a stream with more than half of its recent intervals long (a slow sensor, or a fast
// one mostly silent) is integrated over up to kMaxLearntGapS.
class OdometryTimeline {
 public:
  static constexpr double kGapPeriods = 4.0;
  static constexpr std::size_t kPeriodSamples = 15;
  static constexpr std::size_t kMinPeriodSamples = 3;
  static constexpr double kMaxLearntGapS = 1.0;

  explicit OdometryTimeline(double max_gap_s) : max_gap_s_(max_gap_s) {}

  struct Step {
    InputResult result;      // accepted, or the typed rejection
    double dt_s = 0.0;       // interval to integrate over; 0 for the first sample (the anchor)
    bool integrate = false;  // accepted and not the anchor
  };
  Step advance(const OdometrySample& o);
  std::optional<StampNs> last_stamp_ns() const { return last_stamp_ns_; }
  // The longest interval integrated now: max_gap_s, or what the sensor's period allows.
  double gap_limit_s() const;

 private:
  double max_gap_s_;
  std::optional<StampNs> last_stamp_ns_;
  // The last kPeriodSamples intervals between accepted samples (a ring; gaps included, so that
  // a sensor that turns slower is learnt), and how many there have been.
  std::array<double, kPeriodSamples> intervals_s_{};
  std::size_t interval_count_ = 0;
};

}  // namespace beaconloc
