#pragma once
// The site's ceiling beacons at known positions in the map frame, and the checks a list of
// beacons must pass to become one: whatever its source (a scenario, a recording's beacons.csv,
// a BeaconMap sample from the bus), a map with a repeated id, the reserved id or a position that
// is not a finite number within kMaxMapCoordinateM (core/limits.hpp) is refused whole, with the
// reason and the beacon that caused it; nothing is "repaired" (the first of two ids kept, a NaN
// used).
//
// Seed 003's sites have two kinds of beacon group (ULPS): globally referenced ones, whose beacons'
// map positions are known (Beacon), and locally referenced ones, whose beacons' positions are known
// only in the group's own frame (LocalBeacon) until a calibration finds the group's transform to
// the map. A map holds both; find() gives only beacons with a map position, so that no estimator
// uses a beacon never calibrated as if it were known (a range to one is uncalibrated_beacon).
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_reach.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/rejection_counter.hpp"

namespace beaconloc {

struct Beacon {
  std::uint32_t id = 0;
  Eigen::Vector3d position_map_m = Eigen::Vector3d::Zero();
  std::uint32_t group = 0;  // its beacon group (ULPS, seed 003); 0 where the site is one group
};

// A beacon of a locally referenced group: its position in the group's own frame (x, y in the
// group's plane, z its height as in the map), never a map position.
struct LocalBeacon {
  std::uint32_t id = 0;
  std::uint32_t group = 0;  // never 0: the group names the frame
  Eigen::Vector3d position_group_m = Eigen::Vector3d::Zero();
};

// What a map is made from, as a source lists it. A list of Beacons alone is a map whose beacons
// are all in the map frame.
struct BeaconList {
  BeaconList() = default;
  BeaconList(std::vector<Beacon> map_frame_beacons)  // NOLINT(google-explicit-constructor): the common case
      : map_frame(std::move(map_frame_beacons)) {}
  BeaconList(std::vector<Beacon> map_frame_beacons, std::vector<LocalBeacon> group_frame_beacons)
      : map_frame(std::move(map_frame_beacons)), group_frame(std::move(group_frame_beacons)) {}
  std::vector<Beacon> map_frame;
  std::vector<LocalBeacon> group_frame;
  // Where each beacon is heard (seed 004), by id; a beacon not listed has no known reach.
  std::map<std::uint32_t, BeaconReach> reach;
};

// More beacons than any site has (a slot every 200 ms would take 13 min to fire them all): a
// bound on what one sample may make the localizer and decoder hold.
inline constexpr std::size_t kMaxBeacons = 4096;

enum class BeaconMapProblem {
  kNone,
  kEmpty,               // no beacon at all
  kTooManyBeacons,      // more than kMaxBeacons
  kReservedId,          // kBeaconUnidentified is the id of an anonymous range
  kDuplicateId,         // two beacons with one id
  kNonFinitePosition,   // NaN or infinity in a coordinate
  kPositionOutOfRange,  // a coordinate beyond kMaxMapCoordinateM
  kLocalWithoutGroup,   // a locally referenced beacon in group 0: no frame to be local to
  kGroupBothKinds,      // a group with beacons in the map frame and beacons in its own frame
  kBadReach,            // a reach that is not BeaconReach::valid() (NaN, min >= max, angle beyond pi)
  kReachWithoutBeacon,  // a reach given for an id the map does not hold
};
// Stable snake_case names (Diagnostics reasons: beacon_map.<name>).
const char* to_string(BeaconMapProblem problem);

struct BeaconMapCheck {
  BeaconMapProblem problem = BeaconMapProblem::kNone;
  std::uint32_t beacon_id = 0;  // the beacon that caused it, where one did
  bool ok() const { return problem == BeaconMapProblem::kNone; }
  std::string describe() const;  // "beacon 4: duplicate_id"
};
BeaconMapCheck check_beacons(const BeaconList& beacons);

// Thrown by BeaconMap(beacons) for a list that check_beacons refuses.
class InvalidBeaconMap : public std::invalid_argument {
 public:
  explicit InvalidBeaconMap(const BeaconMapCheck& check)
      : std::invalid_argument("invalid beacon map: " + check.describe()), check_(check) {}
  const BeaconMapCheck& check() const { return check_; }

 private:
  BeaconMapCheck check_;
};

class BeaconMap {
 public:
  BeaconMap() = default;
  // Throws InvalidBeaconMap unless check_beacons(beacons).ok().
  explicit BeaconMap(const BeaconList& beacons);
  explicit BeaconMap(const std::vector<Beacon>& beacons) : BeaconMap(BeaconList(beacons)) {}
  // The map, or nullopt with the reason in *check: for input that may be bad (the bus).
  static std::optional<BeaconMap> from(const BeaconList& beacons, BeaconMapCheck* check);

  // A beacon whose map position is known; nullptr for one only locally referenced.
  const Beacon* find(std::uint32_t id) const {
    auto it = beacons_.find(id);
    return it == beacons_.end() ? nullptr : &it->second;
  }
  // A locally referenced beacon (its position in its group's frame only).
  const LocalBeacon* find_local(std::uint32_t id) const {
    auto it = local_.find(id);
    return it == local_.end() ? nullptr : &it->second;
  }
  bool empty() const { return beacons_.empty() && local_.empty(); }
  std::size_t size() const { return beacons_.size(); }  // beacons with a map position
  std::size_t local_size() const { return local_.size(); }
  std::vector<LocalBeacon> local_beacons() const {
    std::vector<LocalBeacon> out;
    for (const auto& [id, b] : local_) out.push_back(b);
    return out;
  }
  // f(beacon) for every beacon in id order, without the copy beacons() makes.
  template <class F>
  void for_each(F&& f) const {
    for (const auto& entry : beacons_) f(entry.second);
  }
  std::vector<Beacon> beacons() const {
    std::vector<Beacon> out;
    for (const auto& [id, b] : beacons_) out.push_back(b);
    return out;
  }
  // Where a beacon is heard; not known() when the map does not say.
  BeaconReach reach_of(std::uint32_t id) const {
    auto it = reach_.find(id);
    return it == reach_.end() ? BeaconReach{} : it->second;
  }
  BeaconList list() const {
    BeaconList out{beacons(), local_beacons()};
    out.reach = reach_;
    return out;
  }
  // Same beacons at the same positions in the same groups and frames, with the same reach (a gateway that restarts
  // publishes the map again: that is no new map).
  bool operator==(const BeaconMap& other) const;
  bool operator!=(const BeaconMap& other) const { return !(*this == other); }

 private:
  std::map<std::uint32_t, Beacon> beacons_;     // ordered: deterministic iteration
  std::map<std::uint32_t, LocalBeacon> local_;  // locally referenced, by id
  std::map<std::uint32_t, BeaconReach> reach_;   // known reach, by id
};

// How every participant takes a map from the bus: the map, or nullopt with the refusal counted
// in `counts` as beacon_map.<reason> (the caller keeps the map it has).
std::optional<BeaconMap> counted_beacon_map(const BeaconList& beacons, RejectionCounter& counts);

}  // namespace beaconloc
