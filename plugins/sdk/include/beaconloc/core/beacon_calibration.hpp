#pragma once
// Seed 003 Sec. 3.5: what the calibration of a locally referenced group (LRULPS) found: the
// similarity from the group's frame to the map (eq. 41, ERRATA: T_C = [a, b, tx, ty]) and each
// of its beacons' map position (eq. 42-43) with the covariance of that position. A site's
// calibration is the list of its calibrated groups; it is what the BeaconCalibration topic
// carries and what a calibration file keeps (calibration_store.hpp). Every source of one (the
// bus, a file) is checked the same way, and a calibration that fails is refused whole.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "beaconloc/core/time.hpp"

namespace beaconloc {

class BeaconMap;

struct CalibratedBeacon {
  std::uint32_t id = 0;
  Eigen::Vector3d position_map_m = Eigen::Vector3d::Zero();  // z as the group frame gives it
  Eigen::Matrix2d covariance_m2 = Eigen::Matrix2d::Zero();    // of x, y in the map
};

struct GroupCalibration {
  std::uint32_t group = 0;
  StampNs stamp_ns = 0;                                        // the data time it was found at
  Eigen::Vector4d transform = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0);  // [a, b, tx, ty], eq. 41
  double mean_error_m = 0.0;                                   // eq. 46 over the points it was found from
  std::vector<CalibratedBeacon> beacons;
};

struct BeaconCalibration {
  std::vector<GroupCalibration> groups;
  bool operator==(const BeaconCalibration& other) const;
};

enum class CalibrationProblem : std::uint8_t {
  kNone,
  kNonFinite,          // a NaN or an infinity anywhere
  kOutOfRange,         // a position or translation beyond kMaxMapCoordinateM, a stamp < 0, a mean
                       // error < 0
  kDegenerateTransform,  // a scale sqrt(a^2 + b^2) outside [0.5, 2]: no installer's frame is that wrong
  kGroupZero,          // group 0 names no frame
  kDuplicateGroup,     // a group calibrated twice
  kReservedId,         // a beacon with kBeaconUnidentified, an anonymous range's id
  kDuplicateBeacon,    // a beacon in two places
  kEmptyGroup,         // a group with no beacon
  kTooManyBeacons,     // more than kMaxBeacons in all
  kBadCovariance,      // a covariance not symmetric positive semi-definite, or a variance beyond
                       // kMaxMapCoordinateM^2
};
const char* to_string(CalibrationProblem problem);

struct CalibrationCheck {
  CalibrationProblem problem = CalibrationProblem::kNone;
  std::uint32_t group = 0;  // the group it was found in, where one
  bool ok() const { return problem == CalibrationProblem::kNone; }
  std::string describe() const;  // "group 4: bad_covariance"
};
CalibrationCheck check_calibration(const BeaconCalibration& calibration);

// What a site knows is gathered from several sources (robots calibrating, the bus, a file): a
// group in `update` the site does not hold is added; one it holds is replaced when the update's
// is better (its beacons surer: the smaller sum of their covariances' traces; then the later
// stamp; then by value: a total order, so that every localizer keeps the same calibration of a
// group whatever order the versions came in). The groups stay sorted by id, so that equal
// knowledge compares equal. Returns whether `site` changed. Both are checked calibrations; the
// result is one too unless two groups name one beacon (checked by the caller).
bool merge_calibration(BeaconCalibration& site, const BeaconCalibration& update);

// The groups of a calibration that fit the map: each a group the map holds as locally
// referenced, with exactly the map's beacons of that group, each where the group's transform
// (eq. 41) puts the map's beacon (to 1 mm; z the group frame's). A group that does not fit (its
// group unknown or globally referenced, its beacons not the map's, or moved in their group's
// frame since: another site's, or a map changed since) goes to *unfit, when given: it is never
// used, as its beacons are not the map's beacons.
BeaconCalibration calibration_fitting(const BeaconCalibration& calibration, const BeaconMap& map,
                                      std::vector<std::uint32_t>* unfit = nullptr);

}  // namespace beaconloc
