#pragma once
// The decoder without DDS: RawTof -> BeaconRange. Speed of sound from the temperature the
// beacon reported (seed 000, Section II-A), range limits, known beacons, freshness. Every
// rejection is typed and counted.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/rejection.hpp"
#include "beaconloc/core/rejection_counter.hpp"

namespace beaconloc {

// The decoder's refusals are Rejection's TOF reasons (core/rejection.hpp): kNonFiniteTof (NaN or
// Inf), kNegativeTof (<= 0: no flight), kOutOfRangeTof (decoded range outside [min_range_m,
// max_range_m]), kBadTemperature (non-finite or outside [min_temperature_c, max_temperature_c]),
// kNoBeaconMap (an identified beacon before any map), kUnknownBeacon, kStaleTof (fired longer than
// max_age_ns before the robot's newest firing), kDuplicateTof (sequence number and firing stamp
// seen already), kBadStamp (the arrival, fire + TOF, overflows the clock), kTimeJump (fired more
// than max_jump_ns before the newest firing, not yet confirmed).

struct TofDecoderConfig {
  double min_range_m = 0.1;
  double max_range_m = 12.0;
  double range_sigma_m = 0.01;  // seed 000 sigma_dd, measured by the paper
  double min_temperature_c = -30.0;
  double max_temperature_c = 60.0;
  StampNs max_age_ns = kMeasurementHorizonNs;
  // A firing this far (five slots; at least twice max_age_ns) behind the robot's newest is a
  // clock that stepped back, or the true time line after one bad stamp far ahead: refused
  // (time_jump) until a second, different firing within max_age_ns of it confirms it, then
  // followed. Without it one bad stamp would make every good TOF after it stale. (The localizer
  // restarts a robot whose odometry goes back over 1 s.)
  StampNs max_jump_ns = kNsPerSecond;
  // Calibration of the ranging system: range = c * tof / range_scale. 1 for ultrasonic TOF;
  // e.g. 1.069 for the radios of the CMU Plaza recordings (datasets/README.md), whose ranges
  // read 6.9 % long.
  double range_scale = 1.0;
};

struct DecodedRange {
  std::string robot_id;
  RangeMeasurement range;
  bool associated = true;  // false: anonymous pulse, for an estimator that associates
  float quality = 1.0f;
  std::uint64_t source_sequence_number = 0;
};

struct DecodeOutcome {
  std::optional<DecodedRange> range;
  std::optional<Rejection> rejection;
  bool deferred = false;  // held until the beacon map arrives (set_beacon_map decodes it)
};

class TofDecoder {
 public:
  explicit TofDecoder(TofDecoderConfig config = {});  // throws std::invalid_argument
  // TOFs of identified beacons that came before the map are held (up to kMaxBacklog, for
  // max_age_ns) rather than refused: the map and the first TOFs travel on different topics and
  // may arrive in either order. Setting the map decodes them; their ranges are returned.
  std::vector<DecodedRange> set_beacon_map(const BeaconMap& map);
  // A map as received (the bus): one that check_beacons refuses is counted as
  // beacon_map.<reason> and the map in use is kept (nothing decoded then).
  std::vector<DecodedRange> on_beacon_map(const BeaconList& beacons);
  static constexpr std::size_t kMaxBacklog = 64;
  bool has_beacon_map() const { return !map_.empty(); }
  DecodeOutcome decode(const std::string& robot_id, const RawTofSample& tof);
  const RejectionCounter& counts() const { return counts_; }
  const TofDecoderConfig& config() const { return config_; }

 private:
  double range_of(const RawTofSample& tof) const;
  DecodeOutcome reject(Rejection r);
  DecodeOutcome decode_with_map(const std::string& robot_id, const RawTofSample& tof, double range_m);
  struct RobotState {
    StampNs newest_fire_stamp_ns = 0;
    bool seen_any = false;
    std::optional<StampNs> jump_candidate_ns;  // fire stamp of a refused jump, awaiting confirmation
    std::deque<std::pair<std::uint64_t, StampNs>> recent;  // (sequence, fire stamp)
  };
  TofDecoderConfig config_;
  BeaconMap map_;
  std::map<std::string, RobotState> robots_;
  std::deque<std::pair<std::string, RawTofSample>> backlog_;  // before the map
  RejectionCounter counts_;
};

}  // namespace beaconloc
