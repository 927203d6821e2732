#pragma once
// The site's ceiling beacons at known positions in the map frame, and the checks a list of
// beacons must pass to become one: whatever its source (a scenario, a recording's beacons.csv,
// a BeaconMap sample from the bus), a map with a repeated id, the reserved id or a position that
// is not a finite number within kMaxMapCoordinateM (core/limits.hpp) is refused whole, with the
// reason and the beacon that caused it; nothing is "repaired" (the first of two ids kept, a NaN
// used).
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/rejection_counter.hpp"

namespace beaconloc {

struct Beacon {
  std::uint32_t id = 0;
  Eigen::Vector3d position_map_m = Eigen::Vector3d::Zero();
  std::uint32_t group = 0;
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
};
// Stable snake_case names (Diagnostics reasons: beacon_map.<name>).
const char* to_string(BeaconMapProblem problem);

struct BeaconMapCheck {
  BeaconMapProblem problem = BeaconMapProblem::kNone;
  std::uint32_t beacon_id = 0;  // the beacon that caused it, where one did
  bool ok() const { return problem == BeaconMapProblem::kNone; }
  std::string describe() const;  // "beacon 4: duplicate_id"
};
BeaconMapCheck check_beacons(const std::vector<Beacon>& beacons);

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
  explicit BeaconMap(const std::vector<Beacon>& beacons);
  // The map, or nullopt with the reason in *check: for input that may be bad (the bus).
  static std::optional<BeaconMap> from(const std::vector<Beacon>& beacons, BeaconMapCheck* check);

  const Beacon* find(std::uint32_t id) const {
    auto it = beacons_.find(id);
    return it == beacons_.end() ? nullptr : &it->second;
  }
  bool empty() const { return beacons_.empty(); }
  std::size_t size() const { return beacons_.size(); }
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
  // Same beacons at the same positions in the same groups (a gateway that restarts publishes
  // the map again: that is no new map).
  bool operator==(const BeaconMap& other) const;
  bool operator!=(const BeaconMap& other) const { return !(*this == other); }

 private:
  std::map<std::uint32_t, Beacon> beacons_;  // ordered: deterministic iteration
};

// How every participant takes a map from the bus: the map, or nullopt with the refusal counted
// in `counts` as beacon_map.<reason> (the caller keeps the map it has).
std::optional<BeaconMap> counted_beacon_map(const std::vector<Beacon>& beacons, RejectionCounter& counts);

}  // namespace beaconloc
