#include "beaconloc/core/beacon_map.hpp"

#include <cmath>
#include <set>

namespace beaconloc {

const char* to_string(BeaconMapProblem problem) {
  switch (problem) {
    case BeaconMapProblem::kNone:
      return "none";
    case BeaconMapProblem::kEmpty:
      return "empty";
    case BeaconMapProblem::kTooManyBeacons:
      return "too_many_beacons";
    case BeaconMapProblem::kReservedId:
      return "reserved_id";
    case BeaconMapProblem::kDuplicateId:
      return "duplicate_id";
    case BeaconMapProblem::kNonFinitePosition:
      return "non_finite_position";
    case BeaconMapProblem::kPositionOutOfRange:
      return "position_out_of_range";
  }
  return "unknown";
}

std::string BeaconMapCheck::describe() const {
  switch (problem) {
    case BeaconMapProblem::kNone:
    case BeaconMapProblem::kEmpty:
    case BeaconMapProblem::kTooManyBeacons:
      return to_string(problem);
    default:
      return "beacon " + std::to_string(beacon_id) + ": " + to_string(problem);
  }
}

BeaconMapCheck check_beacons(const std::vector<Beacon>& beacons) {
  if (beacons.empty()) return {BeaconMapProblem::kEmpty, 0};
  if (beacons.size() > kMaxBeacons) return {BeaconMapProblem::kTooManyBeacons, 0};
  std::set<std::uint32_t> ids;
  for (const Beacon& b : beacons) {
    if (b.id == kBeaconUnidentified) return {BeaconMapProblem::kReservedId, b.id};
    if (!ids.insert(b.id).second) return {BeaconMapProblem::kDuplicateId, b.id};
    if (!b.position_map_m.allFinite()) return {BeaconMapProblem::kNonFinitePosition, b.id};
    if (b.position_map_m.cwiseAbs().maxCoeff() > kMaxMapCoordinateM)
      return {BeaconMapProblem::kPositionOutOfRange, b.id};
  }
  return {};
}

BeaconMap::BeaconMap(const std::vector<Beacon>& beacons) {
  const BeaconMapCheck check = check_beacons(beacons);
  if (!check.ok()) throw InvalidBeaconMap(check);
  for (const auto& b : beacons) beacons_[b.id] = b;
}

std::optional<BeaconMap> BeaconMap::from(const std::vector<Beacon>& beacons, BeaconMapCheck* check) {
  const BeaconMapCheck c = check_beacons(beacons);
  if (check) *check = c;
  if (!c.ok()) return std::nullopt;
  return BeaconMap(beacons);
}

std::optional<BeaconMap> counted_beacon_map(const std::vector<Beacon>& beacons, RejectionCounter& counts) {
  BeaconMapCheck check;
  std::optional<BeaconMap> map = BeaconMap::from(beacons, &check);
  if (!map) counts.reject(std::string("beacon_map.") + to_string(check.problem));
  return map;
}

bool BeaconMap::operator==(const BeaconMap& other) const {
  if (beacons_.size() != other.beacons_.size()) return false;
  for (auto a = beacons_.begin(), b = other.beacons_.begin(); a != beacons_.end(); ++a, ++b) {
    if (a->first != b->first || a->second.position_map_m != b->second.position_map_m ||
        a->second.group != b->second.group) {
      return false;
    }
  }
  return true;
}

}  // namespace beaconloc
