#include "beaconloc/core/estimator.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <stdexcept>

#include "beaconloc/core/decimal.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/limits.hpp"

namespace beaconloc {

const char* to_string(PoseStatus s) {
  switch (s) {
    case PoseStatus::kInitializing:
      return "initializing";
    case PoseStatus::kOk:
      return "ok";
    case PoseStatus::kDegraded:
      return "degraded";
    case PoseStatus::kLost:
      return "lost";
  }
  return "unknown";
}

const char* kind_name(const EstimatorInput& input) {
  constexpr const char* kNames[] = {"odometry", "range", "laser", "raw_tof", "pulse"};
  static_assert(std::variant_size_v<EstimatorInput> == std::size(kNames), "a name for every kind of input");
  return input.valueless_by_exception() ? "unknown" : kNames[input.index()];
}

bool is_beacon_input(const EstimatorInput& input, BeaconInput kind) {
  switch (kind) {
    case BeaconInput::kRanges:
      return std::holds_alternative<RangeMeasurement>(input);
    case BeaconInput::kRawTof:
      return std::holds_alternative<RawTofSample>(input);
    case BeaconInput::kPulseArrivals:
      return std::holds_alternative<PulseArrivalSample>(input);
  }
  return false;
}

InputResult Estimator::push(const EstimatorInput& input) {
  struct Dispatch {
    Estimator& e;
    InputResult operator()(const OdometrySample& o) const { return e.predict(o); }
    InputResult operator()(const RangeMeasurement& r) const { return e.update(r); }
    InputResult operator()(const LaserScanSample& s) const { return e.update_laser(s); }
    InputResult operator()(const RawTofSample& t) const { return e.update_raw_tof(t); }
    InputResult operator()(const PulseArrivalSample& p) const { return e.update_pulse(p); }
  };
  return std::visit(Dispatch{*this}, input);
}

bool publishable(const PoseEstimate& e) {
  return e.pose_map_base.allFinite() && e.covariance.allFinite() &&
         e.covariance.isApprox(e.covariance.transpose(), 1e-9) &&
         (e.covariance.diagonal().array() >= 0.0).all() &&
         e.pose_map_base.head<2>().cwiseAbs().maxCoeff() <= kMaxMapCoordinateM &&
         std::abs(e.pose_map_base.z()) <= kMaxAngleRad &&
         e.covariance.diagonal().maxCoeff() <= kMaxMapCoordinateM * kMaxMapCoordinateM;
}

std::map<std::string, double> parse_estimator_parameters(const std::vector<std::string>& items,
                                                         const std::string& option_name) {
  std::map<std::string, double> out;
  for (const auto& item : items) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw std::invalid_argument(option_name + " '" + item + "' is not NAME=VALUE");
    }
    const std::string value = item.substr(eq + 1);
    double v = 0.0;
    const NumberError e = parse_decimal(value, v);
    if (e != NumberError::kNone) {
      throw std::invalid_argument(option_name + " '" + item + "': " + number_problem("the value", value, e));
    }
    if (!out.emplace(item.substr(0, eq), v).second) {
      throw std::invalid_argument(option_name + " '" + item + "': " + item.substr(0, eq) + " is given twice");
    }
  }
  return out;
}

const char* to_string(StartupCondition c) {
  switch (c) {
    case StartupCondition::kNoBeaconMap:
      return "no_beacon_map";
    case StartupCondition::kNoOdometry:
      return "no_odometry";
    case StartupCondition::kNeedsInitialPose:
      return "needs_initial_pose";
    case StartupCondition::kTooFewBeacons:
      return "too_few_beacons";
    case StartupCondition::kTooFewRanges:
      return "too_few_ranges";
    case StartupCondition::kFixFailed:
      return "fix_failed";
    case StartupCondition::kMirrorAmbiguous:
      return "mirror_ambiguous";
    case StartupCondition::kPositionTooUncertain:
      return "position_too_uncertain";
    case StartupCondition::kHeadingTooUncertain:
      return "heading_too_uncertain";
    case StartupCondition::kNoDoubleBurst:
      return "no_double_burst";
    case StartupCondition::kNeedsMotion:
      return "needs_motion";
  }
  return "unknown";
}

std::string StartupWait::describe() const {
  char text[160];
  switch (condition) {
    case StartupCondition::kNoBeaconMap:
      std::snprintf(text, sizeof text, "no beacon map");
      break;
    case StartupCondition::kNoOdometry:
      std::snprintf(text, sizeof text, "no odometry yet");
      break;
    case StartupCondition::kNeedsInitialPose:
      std::snprintf(text, sizeof text, "needs an initial pose (--initial-pose or initial_pose)");
      break;
    case StartupCondition::kTooFewBeacons:
      std::snprintf(text, sizeof text, "%.0f of %.0f beacons heard", value, limit);
      break;
    case StartupCondition::kTooFewRanges:
      std::snprintf(text, sizeof text, "%.0f of %.0f ranges", value, limit);
      break;
    case StartupCondition::kFixFailed:
      std::snprintf(text, sizeof text, "no global fix");
      break;
    case StartupCondition::kMirrorAmbiguous:
      std::snprintf(text, sizeof text,
                    "beacons on one line, mirror image fits as well (chi-square margin %.1f < %.1f)", value,
                    limit);
      break;
    case StartupCondition::kPositionTooUncertain:
      std::snprintf(text, sizeof text, "fix too uncertain: position sigma %.2f m > %.2f m", value, limit);
      break;
    case StartupCondition::kHeadingTooUncertain:
      std::snprintf(text, sizeof text, "fix too uncertain: heading sigma %.2f rad > %.2f rad", value, limit);
      break;
    case StartupCondition::kNoDoubleBurst:
      std::snprintf(text, sizeof text, "no double burst heard yet: the beacons cannot be named");
      break;
    case StartupCondition::kNeedsMotion:
      std::snprintf(text, sizeof text, "the heading needs a second fix: moved %.2f m of %.2f m", value, limit);
      break;
  }
  return note.empty() ? std::string(text) : std::string(text) + " (" + note + ")";
}

InputResult check_range_numbers(const RangeMeasurement& r) {
  if (!std::isfinite(r.range_m) || !std::isfinite(r.variance_m2))
    return InputResult::rejected(Rejection::kNonFiniteRange);
  if (!(r.range_m > 0.0) || !(r.variance_m2 > 0.0)) return InputResult::rejected(Rejection::kInvalidRange);
  if (r.range_m > kMaxRangeM || r.variance_m2 > kMaxRangeM * kMaxRangeM)
    return InputResult::rejected(Rejection::kImplausibleRange);
  if (r.stamp_ns < 0) return InputResult::rejected(Rejection::kInvalidStamp);
  return InputResult::ok();
}

InputResult check_range(const RangeMeasurement& r, const BeaconMap& map, std::size_t receiver_count) {
  if (InputResult numbers = check_range_numbers(r); !numbers.accepted) return numbers;
  if (r.beacon_id == kBeaconUnidentified) return InputResult::rejected(Rejection::kUnassociatedRange);
  if (map.empty()) return InputResult::rejected(Rejection::kNoBeaconMap);
  if (!map.find(r.beacon_id)) {
    return InputResult::rejected(map.find_local(r.beacon_id) ? Rejection::kUncalibratedBeacon : Rejection::kUnknownBeacon);
  }
  if (r.receiver_id >= receiver_count) return InputResult::rejected(Rejection::kUnknownReceiver);
  return InputResult::ok();
}

EstimatorRegistry& EstimatorRegistry::instance() {
  static EstimatorRegistry registry;
  return registry;
}

bool EstimatorRegistry::add(const std::string& name, const std::string& description,
                            const std::string& reference_scenario, EstimatorFactory factory) {
  return entries_.emplace(name, Entry{description, reference_scenario, std::move(factory)}).second;
}

std::unique_ptr<Estimator> EstimatorRegistry::create(const std::string& name,
                                                     const EstimatorConfig& config) const {
  auto it = entries_.find(name);
  if (it == entries_.end()) {
    std::string known;
    for (const auto& [n, e] : entries_) known += (known.empty() ? "" : ", ") + n;
    throw UnknownEstimator("unknown estimator '" + name + "' (known: " + known + ")");
  }
  return it->second.factory(config);
}

std::vector<std::string> EstimatorRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [n, e] : entries_) out.push_back(n);
  return out;
}

std::string EstimatorRegistry::description(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? std::string() : it->second.description;
}

std::string EstimatorRegistry::reference_scenario(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? std::string() : it->second.reference_scenario;
}

EstimatorFactory EstimatorRegistry::factory(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? EstimatorFactory() : it->second.factory;
}

InputResult check_initial_pose(const Pose2& pose, const Cov3& c) {
  if (!pose.allFinite() || !c.allFinite() || !c.isApprox(c.transpose(), 1e-9) ||
      Eigen::LLT<Cov3>(c).info() != Eigen::Success) {
    return InputResult::rejected(Rejection::kInvalidInitialPose);
  }
  // Beyond any site (core/limits.hpp), or a standard deviation beyond it:
  // no place to start from.
  if (pose.head<2>().cwiseAbs().maxCoeff() > kMaxMapCoordinateM ||
      c.diagonal().maxCoeff() > kMaxMapCoordinateM * kMaxMapCoordinateM) {
    return InputResult::rejected(Rejection::kImplausibleInitialPose);
  }
  return InputResult::ok();
}

}  // namespace beaconloc
