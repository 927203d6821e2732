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
    case BeaconMapProblem::kLocalWithoutGroup:
      return "local_without_group";
    case BeaconMapProblem::kGroupBothKinds:
      return "group_both_kinds";
    case BeaconMapProblem::kBadReach:
      return "bad_reach";
    case BeaconMapProblem::kReachWithoutBeacon:
      return "reach_without_beacon";
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

namespace {

// The checks every beacon passes, whichever frame its position is in.
BeaconMapProblem check_one(std::uint32_t id, const Eigen::Vector3d& position_m, std::set<std::uint32_t>& ids) {
  if (id == kBeaconUnidentified) return BeaconMapProblem::kReservedId;
  if (!ids.insert(id).second) return BeaconMapProblem::kDuplicateId;
  if (!position_m.allFinite()) return BeaconMapProblem::kNonFinitePosition;
  if (position_m.cwiseAbs().maxCoeff() > kMaxMapCoordinateM) return BeaconMapProblem::kPositionOutOfRange;
  return BeaconMapProblem::kNone;
}

}  // namespace

BeaconMapCheck check_beacons(const BeaconList& beacons) {
  const std::size_t count = beacons.map_frame.size() + beacons.group_frame.size();
  if (count == 0) return {BeaconMapProblem::kEmpty, 0};
  if (count > kMaxBeacons) return {BeaconMapProblem::kTooManyBeacons, 0};
  std::set<std::uint32_t> ids, global_groups;
  for (const Beacon& b : beacons.map_frame) {
    if (const BeaconMapProblem p = check_one(b.id, b.position_map_m, ids); p != BeaconMapProblem::kNone) return {p, b.id};
    global_groups.insert(b.group);
  }
  for (const LocalBeacon& b : beacons.group_frame) {
    if (const BeaconMapProblem p = check_one(b.id, b.position_group_m, ids); p != BeaconMapProblem::kNone) return {p, b.id};
    if (b.group == 0) return {BeaconMapProblem::kLocalWithoutGroup, b.id};
    if (global_groups.count(b.group)) return {BeaconMapProblem::kGroupBothKinds, b.id};
  }
  for (const auto& [id, reach] : beacons.reach) {
    if (!ids.count(id)) return {BeaconMapProblem::kReachWithoutBeacon, id};
    if (!reach.valid()) return {BeaconMapProblem::kBadReach, id};
  }
  return {};
}

BeaconMap::BeaconMap(const BeaconList& beacons) {
  const BeaconMapCheck check = check_beacons(beacons);
  if (!check.ok()) throw InvalidBeaconMap(check);
  for (const auto& b : beacons.map_frame) beacons_[b.id] = b;
  for (const auto& b : beacons.group_frame) local_[b.id] = b;
  for (const auto& [id, reach] : beacons.reach) {
    if (reach.known()) reach_[id] = reach;  // an unknown reach is the default: not held
  }
}

std::optional<BeaconMap> BeaconMap::from(const BeaconList& beacons, BeaconMapCheck* check) {
  const BeaconMapCheck c = check_beacons(beacons);
  if (check) *check = c;
  if (!c.ok()) return std::nullopt;
  return BeaconMap(beacons);
}

std::optional<BeaconMap> counted_beacon_map(const BeaconList& beacons, RejectionCounter& counts) {
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
  if (local_.size() != other.local_.size()) return false;
  for (auto a = local_.begin(), b = other.local_.begin(); a != local_.end(); ++a, ++b) {
    if (a->first != b->first || a->second.position_group_m != b->second.position_group_m ||
        a->second.group != b->second.group) {
      return false;
    }
  }
  return reach_ == other.reach_;
}

}  // namespace beaconloc
