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

namespace {

double covariance_trace_m2(const GroupCalibration& g) {
  double trace = 0.0;
  for (const CalibratedBeacon& b : g.beacons) trace += b.covariance_m2.trace();
  return trace;
}

// Whether `a` is the better calibration of one group: its beacons surer (the smaller sum of their
// covariances' traces: the rule the scan estimator picks forwards or backwards by), then found
// later, then by value. A total order: every localizer keeps the same one, in whatever order the
// versions reached it, and two localizers never hand one group back and forth.
bool better(const GroupCalibration& a, const GroupCalibration& b) {
  const double trace_a = covariance_trace_m2(a), trace_b = covariance_trace_m2(b);
  if (trace_a != trace_b) return trace_a < trace_b;
  if (a.stamp_ns != b.stamp_ns) return a.stamp_ns > b.stamp_ns;
  for (int i = 0; i < 4; ++i) {
    if (a.transform(i) != b.transform(i)) return a.transform(i) < b.transform(i);
  }
  if (a.mean_error_m != b.mean_error_m) return a.mean_error_m < b.mean_error_m;
  if (a.beacons.size() != b.beacons.size()) return a.beacons.size() < b.beacons.size();
  for (std::size_t j = 0; j < a.beacons.size(); ++j) {
    const CalibratedBeacon &x = a.beacons[j], &y = b.beacons[j];
    if (x.id != y.id) return x.id < y.id;
    for (int k = 0; k < 3; ++k) {
      if (x.position_map_m(k) != y.position_map_m(k)) return x.position_map_m(k) < y.position_map_m(k);
    }
    for (int k = 0; k < 4; ++k) {
      if (x.covariance_m2(k) != y.covariance_m2(k)) return x.covariance_m2(k) < y.covariance_m2(k);
    }
  }
  return false;  // the same
}

// How far a calibrated beacon may be from where its group's transform puts the map's beacon: the
// transform and the positions are computed together (eq. 41-43), so only rounding separates them.
constexpr double kFitToleranceM = 1e-3;

}  // namespace

bool merge_calibration(BeaconCalibration& site, const BeaconCalibration& update) {
  bool changed = false;
  for (const GroupCalibration& g : update.groups) {
    const auto it = std::find_if(site.groups.begin(), site.groups.end(),
                                 [&](const GroupCalibration& held) { return held.group == g.group; });
    if (it == site.groups.end()) {
      site.groups.push_back(g);
      changed = true;
    } else if (better(g, *it)) {
      *it = g;
      changed = true;
    }
  }
  std::sort(site.groups.begin(), site.groups.end(),
            [](const GroupCalibration& a, const GroupCalibration& b) { return a.group < b.group; });
  return changed;
}

BeaconCalibration calibration_fitting(const BeaconCalibration& calibration, const BeaconMap& map,
                                      std::vector<std::uint32_t>* unfit) {
  std::map<std::uint32_t, std::map<std::uint32_t, Eigen::Vector3d>> group_beacons;  // group -> id -> position_group_m
  for (const LocalBeacon& b : map.local_beacons()) group_beacons[b.group][b.id] = b.position_group_m;
  BeaconCalibration fitting;
  for (const GroupCalibration& g : calibration.groups) {
    const auto in_map = group_beacons.find(g.group);
    bool fits = in_map != group_beacons.end() && in_map->second.size() == g.beacons.size();
    for (std::size_t i = 0; fits && i < g.beacons.size(); ++i) {
      const CalibratedBeacon& b = g.beacons[i];
      const auto local = in_map->second.find(b.id);
      if (local == in_map->second.end()) {
        fits = false;
        break;
      }
      // Eq. 41 (ERRATA): p_map = [a -b; b a] p_group + [tx, ty]; z as the group frame gives it.
      const Eigen::Vector3d& p = local->second;
      const Eigen::Vector2d placed(g.transform(0) * p.x() - g.transform(1) * p.y() + g.transform(2),
                                   g.transform(1) * p.x() + g.transform(0) * p.y() + g.transform(3));
      fits = (placed - b.position_map_m.head<2>()).norm() <= kFitToleranceM &&
             std::abs(p.z() - b.position_map_m.z()) <= kFitToleranceM;
    }
    if (fits) {
      fitting.groups.push_back(g);
    } else if (unfit) {
      unfit->push_back(g.group);
    }
  }
  return fitting;
}

}  // namespace beaconloc
