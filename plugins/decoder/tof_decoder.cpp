#include "tof_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc {

// Seed 000, Section II-A: distance = c(T) * TOF, with the ranging system's calibration.
double TofDecoder::range_of(const RawTofSample& tof) const {
  return speed_of_sound_mps(tof.beacon_temperature_c) * tof.tof_s / config_.range_scale;
}

DecodeOutcome TofDecoder::reject(Rejection r) {
  counts_.reject(to_string(r));
  DecodeOutcome out;
  out.rejection = r;
  return out;
}

TofDecoder::TofDecoder(TofDecoderConfig config) : config_(config) {
  if (!(config_.range_scale > 0.0) || !std::isfinite(config_.range_scale)) {
    throw std::invalid_argument("range_scale must be a positive number");
  }
  if (!(config_.max_range_m > config_.min_range_m))
    throw std::invalid_argument("max_range_m must exceed min_range_m");
  if (config_.max_age_ns < 0) throw std::invalid_argument("max_age_ns must not be negative");
  if (config_.max_jump_ns < 0) throw std::invalid_argument("max_jump_ns must not be negative");
  // A jump is what lies beyond the useful life of a TOF, never within it.
  const StampNs twice_max_age_ns = config_.max_age_ns > std::numeric_limits<StampNs>::max() / 2
                                       ? std::numeric_limits<StampNs>::max()
                                       : 2 * config_.max_age_ns;
  config_.max_jump_ns = std::max(config_.max_jump_ns, twice_max_age_ns);
}

DecodeOutcome TofDecoder::decode(const std::string& robot_id, const RawTofSample& tof) {
  if (!std::isfinite(tof.tof_s)) return reject(Rejection::kNonFiniteTof);
  if (!(tof.tof_s > 0.0)) return reject(Rejection::kNegativeTof);
  const double t_c = tof.beacon_temperature_c;
  if (!std::isfinite(t_c) || t_c < config_.min_temperature_c || t_c > config_.max_temperature_c) {
    return reject(Rejection::kBadTemperature);
  }
  const double range_m = range_of(tof);
  if (range_m < config_.min_range_m || range_m > config_.max_range_m) {
    return reject(Rejection::kOutOfRangeTof);
  }
  // The arrival, fire stamp + TOF, must be a stamp too (the TOF bound keeps s_to_ns defined).
  if (tof.tof_s >= 9e9 || tof.fire_stamp_ns > std::numeric_limits<StampNs>::max() - s_to_ns(tof.tof_s)) {
    return reject(Rejection::kBadStamp);
  }
  if (tof.beacon_id != kBeaconUnidentified && map_.empty()) {
    // Hold it for the map; what ages out of the backlog, or overflows it, is refused.
    while (!backlog_.empty() &&
           (backlog_.size() >= kMaxBacklog ||
            older_than(backlog_.front().second.fire_stamp_ns, tof.fire_stamp_ns, config_.max_age_ns))) {
      backlog_.pop_front();
      counts_.reject(to_string(Rejection::kNoBeaconMap));
    }
    backlog_.emplace_back(robot_id, tof);
    DecodeOutcome out;
    out.deferred = true;
    return out;
  }
  return decode_with_map(robot_id, tof, range_m);
}

std::vector<DecodedRange> TofDecoder::on_beacon_map(const BeaconList& beacons) {
  const std::optional<BeaconMap> map = counted_beacon_map(beacons, counts_);
  return map ? set_beacon_map(*map) : std::vector<DecodedRange>{};
}

std::vector<DecodedRange> TofDecoder::set_beacon_map(const BeaconMap& map) {
  map_ = map;
  std::vector<DecodedRange> ranges;
  if (map_.empty()) return ranges;
  for (const auto& [robot_id, tof] : backlog_) {
    const auto out = decode_with_map(robot_id, tof, range_of(tof));
    if (out.range) ranges.push_back(*out.range);
  }
  backlog_.clear();
  return ranges;
}

// The checks that need the beacon map, freshness and duplicates; then the range.
DecodeOutcome TofDecoder::decode_with_map(const std::string& robot_id, const RawTofSample& tof,
                                          double range_m) {
  const bool identified = tof.beacon_id != kBeaconUnidentified;
  // A locally referenced beacon's range is a range like any other (its group's calibration needs
  // it); whether its position is known is the estimator's question.
  if (identified && !map_.find(tof.beacon_id) && !map_.find_local(tof.beacon_id)) {
    return reject(Rejection::kUnknownBeacon);
  }

  RobotState& robot = robots_[robot_id];
  bool new_time_line = false;
  // Forwards, any gap is taken: beacons go unheard for seconds (a corridor without beacons, a
  // recording's gaps). Far behind the newest firing is a clock that stepped back, or the
  // robot's time line resuming after one bad stamp far ahead: a second, different firing near
  // this one confirms it, and the decoder follows.
  if (robot.seen_any && older_than(tof.fire_stamp_ns, robot.newest_fire_stamp_ns, config_.max_jump_ns)) {
    const auto& candidate = robot.jump_candidate_ns;
    new_time_line = candidate && *candidate != tof.fire_stamp_ns &&
                    !older_than(tof.fire_stamp_ns, *candidate, config_.max_age_ns) &&
                    !older_than(*candidate, tof.fire_stamp_ns, config_.max_age_ns);
    if (!new_time_line) {
      robot.jump_candidate_ns = tof.fire_stamp_ns;
      return reject(Rejection::kTimeJump);
    }
    robot.recent.clear();
    robot.jump_candidate_ns.reset();
  } else if (robot.seen_any &&
             older_than(tof.fire_stamp_ns, robot.newest_fire_stamp_ns, config_.max_age_ns)) {
    return reject(Rejection::kStaleTof);
  }
  if (!new_time_line) robot.jump_candidate_ns.reset();  // a firing on the time line: no jump pending
  const auto key = std::make_pair(tof.sequence_number, tof.fire_stamp_ns);
  if (std::find(robot.recent.begin(), robot.recent.end(), key) != robot.recent.end()) {
    return reject(Rejection::kDuplicateTof);
  }
  robot.recent.push_back(key);
  if (robot.recent.size() > 64) robot.recent.pop_front();
  robot.newest_fire_stamp_ns = robot.seen_any && !new_time_line
                                   ? std::max(robot.newest_fire_stamp_ns, tof.fire_stamp_ns)
                                   : tof.fire_stamp_ns;
  robot.seen_any = true;

  DecodedRange out;
  out.robot_id = robot_id;
  out.range.stamp_ns = tof.fire_stamp_ns + s_to_ns(tof.tof_s);  // arrival of the pulse
  out.range.beacon_id = tof.beacon_id;
  out.range.receiver_id = tof.receiver_id;
  out.range.range_m = range_m;
  out.range.variance_m2 = config_.range_sigma_m * config_.range_sigma_m;
  out.associated = identified;
  out.source_sequence_number = tof.sequence_number;
  counts_.accept();
  DecodeOutcome outcome;
  outcome.range = out;
  return outcome;
}

}  // namespace beaconloc
