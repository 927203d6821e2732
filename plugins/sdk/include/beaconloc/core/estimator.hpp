#pragma once
// The estimator plugin API. An estimator is pure maths: it is pushed odometry and ranges
// (predict / update) and asked for its estimate. It never reads a clock and never includes a
// DDS header, so the same code runs live, in replay and in tests.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/occupancy_grid.hpp"
#include "beaconloc/core/pose2.hpp"
#include "beaconloc/core/receiver_array.hpp"

namespace beaconloc {

enum class PoseStatus { kInitializing, kOk, kDegraded, kLost };
const char* to_string(PoseStatus s);

struct PoseEstimate {
  StampNs stamp_ns = 0;
  Pose2 pose_map_base = Pose2::Zero();
  Cov3 covariance = Cov3::Identity();
  PoseStatus status = PoseStatus::kInitializing;
};

// The answer to one pushed input: accepted, or rejected with a reason (counted in Diagnostics).
struct InputResult {
  bool accepted = true;
  std::string rejection;  // empty when accepted; a stable snake_case reason otherwise
  static InputResult ok() { return {}; }
  static InputResult rejected(std::string reason) { return {false, std::move(reason)}; }
};

struct EstimatorConfig {
  ReceiverArray receivers;
  std::map<std::string, double> parameters;  // estimator-specific, documented by each plugin
  // The occupancy grid of the map, for estimators with a laser model; null when none was given.
  std::shared_ptr<const OccupancyGrid> occupancy_grid;
  // Where the robot starts, for estimators placed by hand (seed 001 Sec. 4.1); others ignore it.
  std::optional<Pose2> initial_pose;

  double parameter(const std::string& name, double fallback) const {
    auto it = parameters.find(name);
    return it == parameters.end() ? fallback : it->second;
  }
};

// NAME=VALUE items (the --param options) as estimator parameters. Throws std::invalid_argument
// naming the option and the item that is not NAME=VALUE or whose value is not a decimal number
// (core/decimal.hpp: "0x1p1", "inf", "1e400" are refused).
std::map<std::string, double> parse_estimator_parameters(const std::vector<std::string>& items,
                                                         const std::string& option_name);

class Estimator {
 public:
  virtual ~Estimator() = default;
  virtual std::string name() const = 0;
  virtual void set_beacon_map(const BeaconMap& map) = 0;
  virtual InputResult predict(const OdometrySample& odometry) = 0;
  virtual InputResult update(const RangeMeasurement& range) = 0;
  // Laser scans, for the estimators that use them (uses_laser()); the others are never pushed one.
  virtual bool uses_laser() const { return false; }
  virtual InputResult update_laser(const LaserScanSample& /*scan*/) {
    return InputResult::rejected("laser_unused");
  }
  // Anonymous ranges the estimator associated with a beacon since last asked (for evaluation
  // against the simulator's truth); empty for estimators that need identified ranges.
  struct Association {
    StampNs range_stamp_ns;
    std::uint32_t receiver_id;
    std::uint32_t beacon_id;
  };
  virtual std::vector<Association> take_associations() { return {}; }
  // Measurements held for a later step whose fusion then failed (the step itself succeeded),
  // as rejection reasons since last asked: the localizer counts them.
  virtual std::vector<std::string> take_deferred_rejections() { return {}; }
  // Restart from this pose (an operator's or rviz2's initial pose), stamped stamp_ns; the
  // estimators that cannot be placed refuse with a reason.
  virtual InputResult reset(StampNs /*stamp_ns*/, const Pose2& /*pose_map_base*/,
                            const Cov3& /*covariance*/) {
    return InputResult::rejected("reset_unsupported");
  }
  // The current pose; nullopt until the estimator has one.
  virtual std::optional<PoseEstimate> estimate() const = 0;
  // Status from data time alone (the stamps pushed so far).
  virtual PoseStatus status() const = 0;
  // A copy of the whole state, to roll back to when a measurement arrives late
  // (core/out_of_sequence_fusion.hpp).
  virtual std::unique_ptr<Estimator> clone() const = 0;
};

// The checks every range-based estimator makes of a range: finite, positive, from an identified
// beacon of the map, to a receiver the robot has. Accepted, or the typed rejection.
InputResult check_range(const RangeMeasurement& range, const BeaconMap& map, std::size_t receiver_count);

// The checks of a pose to reset an estimator from: finite, and a symmetric positive-definite
// covariance. Accepted, or rejected("invalid_initial_pose").
InputResult check_initial_pose(const Pose2& pose_map_base, const Cov3& covariance);

// Status policy shared by estimators: how long without a fused range the pose stays OK.
struct StalenessPolicy {
  StampNs degraded_after_ns = 1'000'000'000;  // 5 missed beacon slots
  StampNs lost_after_ns = 10'000'000'000;
  PoseStatus classify(StampNs now_ns, StampNs last_correction_ns) const {
    const StampNs age = now_ns - last_correction_ns;
    if (age > lost_after_ns) return PoseStatus::kLost;
    if (age > degraded_after_ns) return PoseStatus::kDegraded;
    return PoseStatus::kOk;
  }
};

}  // namespace beaconloc
