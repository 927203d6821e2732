#include "localizer_core.hpp"

#include "beaconloc/core/estimator_registry.hpp"

namespace beaconloc {

LocalizerCore::LocalizerCore(std::string estimator_name, EstimatorConfig config, std::string robot_filter)
    : estimator_name_(std::move(estimator_name)),
      config_(std::move(config)),
      robot_filter_(std::move(robot_filter)) {
  // Fail at start, not at the first sample, when the name or the configuration is wrong.
  uses_laser_ = EstimatorRegistry::instance().create(estimator_name_, config_)->uses_laser();
}

void LocalizerCore::set_beacon_map(const BeaconMap& map) {
  map_ = map;
  for (auto& [id, r] : robots_) r.estimator->set_beacon_map(map_);
}

LocalizerCore::Robot* LocalizerCore::robot(const std::string& robot_id, const char* kind) {
  if (!robot_filter_.empty() && robot_id != robot_filter_) {
    counts_.reject(std::string(kind) + ".other_robot");
    return nullptr;
  }
  if (robot_id.empty()) {
    counts_.reject(std::string(kind) + ".empty_robot_id");
    return nullptr;
  }
  auto it = robots_.find(robot_id);
  if (it == robots_.end()) {
    Robot r;
    r.estimator = EstimatorRegistry::instance().create(estimator_name_, config_);
    r.estimator->set_beacon_map(map_);
    it = robots_.emplace(robot_id, std::move(r)).first;
  }
  return &it->second;
}

std::optional<LocalizerOutput> LocalizerCore::on_odometry(const std::string& robot_id,
                                                          const OdometrySample& odometry) {
  Robot* r = robot(robot_id, "odometry");
  if (!r) return std::nullopt;
  const InputResult result = r->estimator->predict(odometry);
  for (const auto& reason : r->estimator->take_deferred_rejections()) counts_.reject("deferred." + reason);
  if (!result.accepted) {
    counts_.reject("odometry." + result.rejection);
    return std::nullopt;
  }
  counts_.accept();
  auto estimate = r->estimator->estimate();
  if (!estimate) return std::nullopt;
  LocalizerOutput out{robot_id, *estimate, {r->beacons_used.begin(), r->beacons_used.end()}};
  r->beacons_used.clear();
  return out;
}

void LocalizerCore::on_range(const std::string& robot_id, const RangeMeasurement& range) {
  Robot* r = robot(robot_id, "range");
  if (!r) return;
  const InputResult result = r->estimator->update(range);
  if (!result.accepted) {
    counts_.reject("range." + result.rejection);
    return;
  }
  counts_.accept();
  r->beacons_used.insert(range.beacon_id);
}

void LocalizerCore::on_laser(const std::string& robot_id, const LaserScanSample& scan) {
  if (!uses_laser_) return;  // the participant does not subscribe to scans then; nothing to count
  Robot* r = robot(robot_id, "laser");
  if (!r) return;
  const InputResult result = r->estimator->update_laser(scan);
  if (!result.accepted) {
    counts_.reject("laser." + result.rejection);
    return;
  }
  counts_.accept();
}

void LocalizerCore::on_initial_pose(const std::string& robot_id, StampNs stamp_ns, const Pose2& pose,
                                    const Cov3& covariance) {
  Robot* r = robot(robot_id, "initial_pose");
  if (!r) return;
  const InputResult result = r->estimator->reset(stamp_ns, pose, covariance);
  if (!result.accepted) {
    counts_.reject("initial_pose." + result.rejection);
    return;
  }
  counts_.accept();
}

std::vector<Estimator::Association> LocalizerCore::take_associations(const std::string& robot_id) {
  auto it = robots_.find(robot_id);
  return it == robots_.end() ? std::vector<Estimator::Association>{}
                             : it->second.estimator->take_associations();
}

PoseStatus LocalizerCore::worst_status() const {
  PoseStatus worst = PoseStatus::kOk;
  auto rank = [](PoseStatus s) {
    switch (s) {
      case PoseStatus::kOk:
        return 0;
      case PoseStatus::kInitializing:
        return 1;
      case PoseStatus::kDegraded:
        return 2;
      case PoseStatus::kLost:
        return 3;
    }
    return 3;
  };
  for (const auto& [id, r] : robots_) {
    if (rank(r.estimator->status()) > rank(worst)) worst = r.estimator->status();
  }
  return worst;
}

}  // namespace beaconloc
