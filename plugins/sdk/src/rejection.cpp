#include "beaconloc/core/rejection.hpp"

namespace beaconloc {

const char* to_string(Rejection r) {
  switch (r) {
    case Rejection::kNonFiniteOdometry: return "non_finite_odometry";
    case Rejection::kInvalidStamp: return "invalid_stamp";
    case Rejection::kInvalidWheelBase: return "invalid_wheel_base";
    case Rejection::kImplausibleWheelBase: return "implausible_wheel_base";
    case Rejection::kImplausibleWheelSpeed: return "implausible_wheel_speed";
    case Rejection::kInvalidOdometryCovariance: return "invalid_odometry_covariance";
    case Rejection::kDuplicateOdometry: return "duplicate_odometry";
    case Rejection::kOutOfOrderOdometry: return "out_of_order_odometry";
    case Rejection::kOdometryGap: return "odometry_gap";
    case Rejection::kImplausibleOdomPose: return "implausible_odom_pose";
    case Rejection::kNonFiniteRange: return "non_finite_range";
    case Rejection::kInvalidRange: return "invalid_range";
    case Rejection::kImplausibleRange: return "implausible_range";
    case Rejection::kUnassociatedRange: return "unassociated_range";
    case Rejection::kNoBeaconMap: return "no_beacon_map";
    case Rejection::kUnknownBeacon: return "unknown_beacon";
    case Rejection::kUncalibratedBeacon: return "uncalibrated_beacon";
    case Rejection::kUnknownReceiver: return "unknown_receiver";
    case Rejection::kStaleRange: return "stale_range";
    case Rejection::kRangesWithoutOdometry: return "ranges_without_odometry";
    case Rejection::kNoBeaconToAssociate: return "no_beacon_to_associate";
    case Rejection::kBeaconsUnused: return "beacons_unused";
    case Rejection::kMalformedScan: return "malformed_scan";
    case Rejection::kNoUsableBeams: return "no_usable_beams";
    case Rejection::kStaleScan: return "stale_scan";
    case Rejection::kLaserUnused: return "laser_unused";
    case Rejection::kRawTofUnused: return "raw_tof_unused";
    case Rejection::kPulseUnused: return "pulse_unused";
    case Rejection::kPulseBeforeDoubleBurst: return "pulse_before_double_burst";
    case Rejection::kPulseBetweenSlots: return "pulse_between_slots";
    case Rejection::kPulseLate: return "pulse_late";
    case Rejection::kPulseTooFarAhead: return "pulse_too_far_ahead";
    case Rejection::kStartupFitFailed: return "startup_fit_failed";
    case Rejection::kDuplicatePulse: return "duplicate_pulse";
    case Rejection::kDuplicateRange: return "duplicate_range";
    case Rejection::kTooManyRangesInEpoch: return "too_many_ranges_in_epoch";
    case Rejection::kTooManyPulsesInSlot: return "too_many_pulses_in_slot";
    case Rejection::kBeaconMapUnusable: return "beacon_map_unusable";
    case Rejection::kTooLate: return "too_late";
    case Rejection::kAheadOfOdometry: return "ahead_of_odometry";
    case Rejection::kGatedNis: return "gated_nis";
    case Rejection::kEchoOfFiring: return "echo_of_firing";
    case Rejection::kLongerThanTheReceiverMoved: return "longer_than_the_receiver_moved";
    case Rejection::kSingularInnovation: return "singular_innovation";
    case Rejection::kCovarianceNotPositiveDefinite: return "covariance_not_positive_definite";
    case Rejection::kHInfinityBoundNotMet: return "h_infinity_bound_not_met";
    case Rejection::kNonFiniteModel: return "non_finite_model";
    case Rejection::kSizeMismatch: return "size_mismatch";
    case Rejection::kStaleSigmaPoints: return "stale_sigma_points";
    case Rejection::kEveryComponentGated: return "every_component_gated";
    case Rejection::kNoInitialPose: return "no_initial_pose";
    case Rejection::kResetUnsupported: return "reset_unsupported";
    case Rejection::kInvalidInitialPose: return "invalid_initial_pose";
    case Rejection::kImplausibleInitialPose: return "implausible_initial_pose";
    // The decoder's names predate this enumeration and stay as they were on the wire.
    case Rejection::kNonFiniteTof: return "non_finite_tof";
    case Rejection::kNegativeTof: return "negative_tof";
    case Rejection::kOutOfRangeTof: return "out_of_range_tof";
    case Rejection::kBadTemperature: return "bad_temperature";
    case Rejection::kStaleTof: return "stale";
    case Rejection::kDuplicateTof: return "duplicate";
    case Rejection::kBadStamp: return "bad_stamp";
    case Rejection::kTimeJump: return "time_jump";
  }
  return "unknown";
}

std::optional<Rejection> rejection_for(FilterOutcome outcome) {
  switch (outcome) {
    case FilterOutcome::kGated: return Rejection::kGatedNis;
    case FilterOutcome::kSingularInnovation: return Rejection::kSingularInnovation;
    case FilterOutcome::kNotPositiveDefinite: return Rejection::kCovarianceNotPositiveDefinite;
    case FilterOutcome::kBoundNotMet: return Rejection::kHInfinityBoundNotMet;
    case FilterOutcome::kNonFinite: return Rejection::kNonFiniteModel;
    case FilterOutcome::kSizeMismatch: return Rejection::kSizeMismatch;
    case FilterOutcome::kStaleSigmaPoints: return Rejection::kStaleSigmaPoints;
    case FilterOutcome::kEveryComponentGated: return Rejection::kEveryComponentGated;
    case FilterOutcome::kApplied: return std::nullopt;
  }
  return Rejection::kNonFiniteModel;  // an outcome outside the enumeration: refused all the same
}

}  // namespace beaconloc
