#include "beaconloc/core/beacon_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/limits.hpp"

namespace beaconloc {
namespace {

// The bounds on a similarity's scale: a group's frame is in metres like the map's.
constexpr double kMinScale = 0.5;
constexpr double kMaxScale = 2.0;

bool within_site(double coordinate_m) { return std::abs(coordinate_m) <= kMaxMapCoordinateM; }

CalibrationProblem check_group(const GroupCalibration& g, std::set<std::uint32_t>& beacon_ids, std::size_t& beacons) {
  if (g.group == 0) return CalibrationProblem::kGroupZero;
  if (!g.transform.allFinite() || !std::isfinite(g.mean_error_m)) return CalibrationProblem::kNonFinite;
  if (g.stamp_ns < 0 || !(g.mean_error_m >= 0.0) || !within_site(g.transform(2)) || !within_site(g.transform(3))) {
    return CalibrationProblem::kOutOfRange;
  }
  const double scale = g.transform.head<2>().norm();
  if (!(scale >= kMinScale && scale <= kMaxScale)) return CalibrationProblem::kDegenerateTransform;
  if (g.beacons.empty()) return CalibrationProblem::kEmptyGroup;
  for (const CalibratedBeacon& b : g.beacons) {
    if (!b.position_map_m.allFinite() || !b.covariance_m2.allFinite()) return CalibrationProblem::kNonFinite;
    if (!within_site(b.position_map_m.x()) || !within_site(b.position_map_m.y()) || !within_site(b.position_map_m.z())) {
      return CalibrationProblem::kOutOfRange;
    }
    const Eigen::Matrix2d& c = b.covariance_m2;
    if (c(0, 1) != c(1, 0) || c(0, 0) < 0.0 || c(1, 1) < 0.0 || c(0, 0) * c(1, 1) < c(0, 1) * c(0, 1) ||
        c(0, 0) > kMaxMapCoordinateM * kMaxMapCoordinateM || c(1, 1) > kMaxMapCoordinateM * kMaxMapCoordinateM) {
      return CalibrationProblem::kBadCovariance;
    }
    if (b.id == kBeaconUnidentified) return CalibrationProblem::kReservedId;
    if (!beacon_ids.insert(b.id).second) return CalibrationProblem::kDuplicateBeacon;
    if (++beacons > kMaxBeacons) return CalibrationProblem::kTooManyBeacons;
  }
  return CalibrationProblem::kNone;
}

}  // namespace

bool BeaconCalibration::operator==(const BeaconCalibration& other) const {
  if (groups.size() != other.groups.size()) return false;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const GroupCalibration& a = groups[i];
    const GroupCalibration& b = other.groups[i];
    if (a.group != b.group || a.stamp_ns != b.stamp_ns || a.transform != b.transform ||
        a.mean_error_m != b.mean_error_m || a.beacons.size() != b.beacons.size()) {
      return false;
    }
    for (std::size_t j = 0; j < a.beacons.size(); ++j) {
      if (a.beacons[j].id != b.beacons[j].id || a.beacons[j].position_map_m != b.beacons[j].position_map_m ||
          a.beacons[j].covariance_m2 != b.beacons[j].covariance_m2) {
        return false;
      }
    }
  }
  return true;
}

const char* to_string(CalibrationProblem problem) {
  switch (problem) {
    case CalibrationProblem::kNone: return "none";
    case CalibrationProblem::kNonFinite: return "non_finite";
    case CalibrationProblem::kOutOfRange: return "out_of_range";
    case CalibrationProblem::kDegenerateTransform: return "degenerate_transform";
    case CalibrationProblem::kGroupZero: return "group_zero";
    case CalibrationProblem::kDuplicateGroup: return "duplicate_group";
    case CalibrationProblem::kReservedId: return "reserved_id";
    case CalibrationProblem::kDuplicateBeacon: return "duplicate_beacon";
    case CalibrationProblem::kEmptyGroup: return "empty_group";
    case CalibrationProblem::kTooManyBeacons: return "too_many_beacons";
    case CalibrationProblem::kBadCovariance: return "bad_covariance";
  }
  return "unknown";
}

std::string CalibrationCheck::describe() const {
  return "group " + std::to_string(group) + ": " + to_string(problem);
}

CalibrationCheck check_calibration(const BeaconCalibration& calibration) {
  std::set<std::uint32_t> groups;
  std::set<std::uint32_t> beacon_ids;
  std::size_t beacons = 0;
  for (const GroupCalibration& g : calibration.groups) {
    if (!groups.insert(g.group).second) return {CalibrationProblem::kDuplicateGroup, g.group};
    const CalibrationProblem p = check_group(g, beacon_ids, beacons);
    if (p != CalibrationProblem::kNone) return {p, g.group};
  }
  return {};
}

bool merge_calibration(BeaconCalibration& site, const BeaconCalibration& update) {
  const BeaconCalibration before = site;
  for (const GroupCalibration& g : update.groups) {
    const auto it = std::find_if(site.groups.begin(), site.groups.end(),
                                 [&](const GroupCalibration& held) { return held.group == g.group; });
    if (it == site.groups.end()) {
      site.groups.push_back(g);
    } else {
      *it = g;
    }
  }
  std::sort(site.groups.begin(), site.groups.end(),
            [](const GroupCalibration& a, const GroupCalibration& b) { return a.group < b.group; });
  return !(site == before);
}

BeaconCalibration calibration_fitting(const BeaconCalibration& calibration, const BeaconMap& map,
                                      std::vector<std::uint32_t>* unfit) {
  std::map<std::uint32_t, std::set<std::uint32_t>> group_beacons;  // the map's locally referenced groups
  for (const LocalBeacon& b : map.local_beacons()) group_beacons[b.group].insert(b.id);
  BeaconCalibration fitting;
  for (const GroupCalibration& g : calibration.groups) {
    std::set<std::uint32_t> ids;
    for (const CalibratedBeacon& b : g.beacons) ids.insert(b.id);
    const auto in_map = group_beacons.find(g.group);
    if (in_map != group_beacons.end() && in_map->second == ids && ids.size() == g.beacons.size()) {
      fitting.groups.push_back(g);
    } else if (unfit) {
      unfit->push_back(g.group);
    }
  }
  return fitting;
}

}  // namespace beaconloc
