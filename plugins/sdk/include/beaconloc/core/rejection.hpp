#pragma once
// Why an input was refused: one enumeration across the decoder, the localizer, its estimators and
// the bridge's odometry (issue 14), each with a stable snake_case name (to_string) that goes on
// the wire in Diagnostics. Code decides on the enumerator, never on the name. The same bad input
// gets the same reason wherever it is checked (core/estimator.hpp check_range_numbers,
// core/odometry_timeline.hpp check_odometry_numbers).
#include <cstdint>
#include <optional>
#include <ostream>

#include "beaconloc/core/filters/outcome.hpp"

namespace beaconloc {

enum class Rejection : std::uint8_t {
  // Odometry (check_odometry_numbers, OdometryTimeline).
  kNonFiniteOdometry,
  kInvalidStamp,  // a stamp < 0 (any input)
  kInvalidWheelBase,
  kImplausibleWheelBase,
  kImplausibleWheelSpeed,
  kInvalidOdometryCovariance,
  kDuplicateOdometry,
  kOutOfOrderOdometry,
  kOdometryGap,          // accepted as the new anchor; the interval before it not integrated
  kImplausibleOdomPose,  // the bridge's integrated odom pose left the site
  // Ranges (check_range_numbers, check_range).
  kNonFiniteRange,
  kInvalidRange,
  kImplausibleRange,
  kUnassociatedRange,  // anonymous, to an estimator that needs identified beacons
  kNoBeaconMap,
  kUnknownBeacon,
  kUncalibratedBeacon,  // locally referenced (seed 003): no map position until calibrated
  kUnknownReceiver,
  kStaleRange,
  kRangesWithoutOdometry,
  kNoBeaconToAssociate,
  kBeaconsUnused,  // an estimator mode that takes no beacon ranges
  kDuplicateRange,         // a beacon's range at a stamp heard already (a duplicate delivery)
  kTooManyRangesInEpoch,   // a flood: more ranges in one group's epoch than any group has beacons
  // Laser scans.
  kMalformedScan,
  kNoUsableBeams,
  kStaleScan,
  kLaserUnused,
  kRawTofUnused,  // a raw time of flight, to an estimator of decoded ranges
  // Pulse arrivals without a firing time (seed 002).
  kPulseUnused,             // to an estimator that does not track the beacons' cycle
  kPulseBeforeDoubleBurst,  // heard before the first double burst: no beacon can be named yet
  kPulseBetweenSlots,       // later than the longest flight after any firing: not a direct pulse
  kPulseLate,               // of a slot the filter has moved past
  kPulseTooFarAhead,        // further ahead of the filter's cycle than it can step (kMaxSlotsAhead)
  kStartupFitFailed,        // the start-up fit this pulse completed found no state that explains the pulses
  kDuplicatePulse,          // a receiver's arrival stamp heard already
  kTooManyPulsesInSlot,     // a flood: more pulses in one slot than echoes explain
  kBeaconMapUnusable,       // no marked beacon, too few beacons, or slots that would be ambiguous
  // Out-of-sequence fusion (core/out_of_sequence_fusion.hpp).
  kTooLate,
  kAheadOfOdometry,
  // A filter's update or prediction not applied (core/filters/outcome.hpp).
  kGatedNis,
  kEchoOfFiring,  // longer than another receiver's range of the same firing allows (ranges_of_one_firing_agree)
  kLongerThanTheReceiverMoved,  // longer than its beacon's previous range by more than the receiver moved since (an echo)
  kSingularInnovation,
  kCovarianceNotPositiveDefinite,
  kHInfinityBoundNotMet,
  kNonFiniteModel,
  kSizeMismatch,
  kStaleSigmaPoints,
  kEveryComponentGated,  // every beam of a scan (every component) an outlier on its own
  // Placing an estimator.
  kNoInitialPose,
  kResetUnsupported,
  kInvalidInitialPose,
  kImplausibleInitialPose,
  // Time of flight (the decoder).
  kNonFiniteTof,
  kNegativeTof,
  kOutOfRangeTof,
  kBadTemperature,
  kStaleTof,
  kDuplicateTof,
  kBadStamp,
  kTimeJump,
};
inline constexpr int kRejectionCount = static_cast<int>(Rejection::kTimeJump) + 1;

// The stable name on the wire.
const char* to_string(Rejection r);
inline std::ostream& operator<<(std::ostream& out, Rejection r) { return out << to_string(r); }

// The rejection a filter's outcome means for the measurement; none for kApplied.
std::optional<Rejection> rejection_for(FilterOutcome outcome);

}  // namespace beaconloc
