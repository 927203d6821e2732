#include "localizer_core.hpp"

#include <cmath>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/filters/symmetric.hpp"

namespace beaconloc {

LocalizerCore::LocalizerCore(std::string estimator_name, EstimatorConfig config, std::string robot_filter)
    : estimator_name_(std::move(estimator_name)),
      config_(std::move(config)),
      robot_filter_(std::move(robot_filter)) {
  // Fail at start, not at the first sample, when the name or the configuration is wrong.
  const auto probe = EstimatorRegistry::instance().create(estimator_name_, config_);
  uses_laser_ = probe->uses_laser();
  localizes_from_beacons_ = probe->localizes_from_beacons();
  beacon_input_ = probe->beacon_input();
  uses_calibration_ = probe->uses_calibration();
}

bool LocalizerCore::on_calibration(const BeaconCalibration& calibration) {
  if (!uses_calibration_) return false;  // its estimator calibrates nothing and uses nothing
  const CalibrationCheck check = check_calibration(calibration);
  if (!check.ok()) {
    counts_.reject(std::string("calibration.") + to_string(check.problem));
    return false;
  }
  counts_.accept();
  return merge_into_site(calibration, nullptr);
}

bool LocalizerCore::merge_into_site(const BeaconCalibration& calibration, const Robot* source) {
  bool changed = false;
  for (const GroupCalibration& g : calibration.groups) {
    const BeaconCalibration one{{g}};
    if (!map_.empty() && calibration_fitting(one, map_).groups.empty()) {
      counts_.reject("calibration.not_on_map");  // another site's, or measured on another map
      continue;
    }
    BeaconCalibration merged = calibration_;
    if (!merge_calibration(merged, one)) continue;  // held already, or a better one is
    // A beacon another group holds: the group is refused, the rest goes on.
    if (const CalibrationCheck check = check_calibration(merged); !check.ok()) {
      counts_.reject(std::string("calibration.") + to_string(check.problem));
      continue;
    }
    calibration_ = std::move(merged);
    changed = true;
  }
  if (!changed) return false;
  ++calibration_revision_;
  // Not back to the robot that found it: what it holds is its own, and the copies its late
  // measurements replay from must find it again themselves (the backwards drive counts on it).
  for (auto& [id, r] : robots_) {
    if (&r != source) give_calibration(r);
  }
  return true;
}

void LocalizerCore::drop_calibration_off_the_map() {
  std::vector<std::uint32_t> unfit;
  const BeaconCalibration fitting = calibration_fitting(calibration_, map_, &unfit);
  if (unfit.empty()) return;
  counts_.reject("calibration.not_on_map", unfit.size());
  calibration_ = fitting;
  ++calibration_revision_;
}

void LocalizerCore::give_calibration(Robot& r) {
  if (!uses_calibration_ || map_.empty() || calibration_.groups.empty()) return;
  if (!r.fusion.use_calibration(calibration_)) counts_.reject("calibration.refused_by_estimator");
  r.fusion.take_calibration_update();  // the site's again: nothing new to it
}

void LocalizerCore::take_calibration(Robot& r) {
  if (!uses_calibration_) return;
  // Its own finding, checked as anything else: an estimator's fault is counted, not spread.
  if (const std::optional<BeaconCalibration> found = r.fusion.take_calibration_update()) {
    if (const CalibrationCheck check = check_calibration(*found); !check.ok()) {
      counts_.reject(std::string("calibration.") + to_string(check.problem));
    } else {
      merge_into_site(*found, &r);
    }
  }
}

bool LocalizerCore::on_beacon_map(const BeaconList& beacons) {
  const std::optional<BeaconMap> map = counted_beacon_map(beacons, counts_);
  if (map) set_beacon_map(*map);
  return map.has_value();
}

void LocalizerCore::set_beacon_map(const BeaconMap& map) {
  if (map == map_) return;
  const bool first = map_.empty();
  map_ = map;
  if (!first) ++beacon_map_changes_;
  // Groups calibrated on another map (or received before the first) that this one does not fit
  // are dropped: their beacons are not this map's.
  drop_calibration_off_the_map();
  for (auto& [id, r] : robots_) {
    if (first) {
      r.fusion.set_beacon_map(map_);  // nothing it holds came from beacons yet
      give_calibration(r);
    } else {
      restart_robot(r);
    }
  }
}

InputResult LocalizerCore::restart_robot(Robot& r, const OdometrySample* next) {
  const std::optional<PoseEstimate> before = r.fusion.estimator().estimate();
  EstimatorConfig restart = config_;
  restart.initial_pose.reset();  // not the run's start pose
  r = Robot(EstimatorRegistry::instance().create(estimator_name_, restart));
  r.fusion.set_beacon_map(map_);
  give_calibration(r);
  const InputResult result = next ? r.fusion.push(*next) : InputResult::ok();
  if (!r.fusion.estimator().localizes_from_beacons() && before && publishable(*before) && result.accepted) {
    // Placed where it was, less sure by 0.1 m and 0.1 rad (standard deviations).
    const Cov3 inflated = before->covariance + Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal().toDenseMatrix();
    r.fusion.reset(next ? next->stamp_ns : before->stamp_ns, before->pose_map_base, inflated);
  }
  return result;
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
    it = robots_.emplace(robot_id, Robot(EstimatorRegistry::instance().create(estimator_name_, config_)))
             .first;
    it->second.fusion.set_beacon_map(map_);
    give_calibration(it->second);
  }
  return &it->second;
}

std::optional<LocalizerOutput> LocalizerCore::on_odometry(const std::string& robot_id,
                                                          const OdometrySample& odometry) {
  Robot* r = robot(robot_id, "odometry");
  if (!r) return std::nullopt;
  r->odometry_deadlines_missed = 0;  // the bus delivers odometry again
  InputResult result = r->fusion.push(odometry);
  take_calibration(*r);
  for (const auto& reason : r->fusion.take_deferred_rejections()) counts_.reject("deferred.", reason);
  if (!result.accepted && result.rejection == Rejection::kOutOfOrderOdometry && clock_jumped_back(*r, odometry)) {
    // The robot's clock stepped back (a restarted gateway replaying, a reset clock): what the
    // estimator holds belongs to the old time line. A new one starts on the new time line
    // (restart_robot: re-localized from the beacons; the old pose is no evidence of where the
    // robot is now, a replay starts again where the robot was back then).
    counts_.reject("odometry.clock_jumped_back");
    result = restart_robot(*r, &odometry);
  }
  if (!result.accepted) {
    counts_.reject("odometry.", *result.rejection);
    return std::nullopt;
  }
  r->jump_candidate_ns.reset();
  counts_.accept();
  return output(robot_id, *r);
}

std::optional<LocalizerOutput> LocalizerCore::output(const std::string& robot_id, Robot& r) {
  auto estimate = r.fusion.estimator().estimate();
  if (!estimate) return std::nullopt;
  if (!publishable(*estimate)) {
    // Never published: an estimate with a non-finite number or a broken covariance. The
    // estimator that made it cannot be trusted either: the robot starts again from the beacons.
    counts_.reject("estimate.unusable");
    restart_robot(r);
    return std::nullopt;
  }
  estimate->status = r.status();
  // An estimator's covariance is symmetric up to its own rounding (an odometry step's F P F^T, a
  // correction carried forward): published exactly symmetric, as ROS 2 consumers take a
  // covariance and a recording's reader checks it (a difference in the last bit, seen on
  // range_ekf's poses).
  estimate->covariance = symmetrized(estimate->covariance);
  LocalizerOutput out{robot_id, *estimate, {r.beacons_used.begin(), r.beacons_used.end()}, {}};
  r.beacons_used.clear();
  // Compared as a difference: a stamp near the clock's end must not overflow.
  if (!r.state_sent_ns || estimate->stamp_ns < *r.state_sent_ns ||
      estimate->stamp_ns - *r.state_sent_ns >= kEstimatorStatePeriodNs) {
    out.state = r.fusion.estimator().state_values();
    // Like a pose, never a non-finite number out: an estimator whose state is not finite has a
    // pose no better (and publishable() would have caught most); the state is dropped, counted.
    for (const Estimator::StateValue& v : out.state) {
      if (!std::isfinite(v.value) || !std::isfinite(v.sigma) || !(v.sigma >= 0.0)) {
        counts_.reject("estimate.unusable_state");
        out.state.clear();
        break;
      }
    }
    if (!out.state.empty()) r.state_sent_ns = estimate->stamp_ns;
  }
  return out;
}

namespace {
bool same_estimate(const std::optional<PoseEstimate>& a, const std::optional<PoseEstimate>& b) {
  if (a.has_value() != b.has_value()) return false;
  return !a || (a->stamp_ns == b->stamp_ns && a->pose_map_base == b->pose_map_base &&
                a->covariance == b->covariance);
}
}  // namespace

std::optional<LocalizerOutput> LocalizerCore::correction_output(const std::string& robot_id, Robot& r,
                                                                const std::optional<PoseEstimate>& before) {
  if (same_estimate(before, r.fusion.estimator().estimate())) return std::nullopt;  // held, or gated
  return output(robot_id, r);
}

std::optional<LocalizerOutput> LocalizerCore::on_range(const std::string& robot_id,
                                                       const RangeMeasurement& range) {
  return on_input(robot_id, range);  // none unless beacon_input() is kRanges: not subscribed then
}

std::optional<LocalizerOutput> LocalizerCore::on_laser(const std::string& robot_id,
                                                       const LaserScanSample& scan) {
  return on_input(robot_id, scan);  // none unless uses_laser(): the participant does not subscribe then
}

std::optional<LocalizerOutput> LocalizerCore::on_raw_tof(const std::string& robot_id, const RawTofSample& tof) {
  return on_input(robot_id, tof);  // none unless beacon_input() is kRawTof: not subscribed then
}

std::optional<LocalizerOutput> LocalizerCore::on_pulse(const std::string& robot_id, const PulseArrivalSample& pulse) {
  return on_input(robot_id, pulse);  // none unless beacon_input() is kPulseArrivals: not subscribed then
}

std::optional<LocalizerOutput> LocalizerCore::on_input(const std::string& robot_id, EstimatorInput input) {
  if (const auto* odometry = std::get_if<OdometrySample>(&input)) return on_odometry(robot_id, *odometry);
  // What the estimator does not take, the participant does not subscribe to: scans for an
  // estimator without a laser model; beacon measurements of another kind than its beacon_input().
  if (std::holds_alternative<LaserScanSample>(input)) {
    if (!uses_laser_) return std::nullopt;
  } else if (!is_beacon_input(input, beacon_input_)) {
    return std::nullopt;
  }
  return on_measurement(robot_id, std::move(input));
}

namespace {
// The beacon a measurement is from, for LocalizerOutput::beacons_used; none for a scan.
std::optional<std::uint32_t> beacon_of(const EstimatorInput& input) {
  if (const auto* range = std::get_if<RangeMeasurement>(&input)) return range->beacon_id;
  if (const auto* tof = std::get_if<RawTofSample>(&input)) return tof->beacon_id;
  return std::nullopt;
}
}  // namespace

std::optional<LocalizerOutput> LocalizerCore::on_measurement(const std::string& robot_id, EstimatorInput input) {
  const std::string kind = kind_name(input);
  Robot* r = robot(robot_id, kind.c_str());
  if (!r) return std::nullopt;
  const std::optional<std::uint32_t> beacon = beacon_of(input);
  // The bus delivers beacon measurements again (of any kind, pulses too); whether they fit is the
  // estimator's call.
  if (is_beacon_input(input, beacon_input_)) r->ranges_silent = false;
  const std::optional<PoseEstimate> before = r->fusion.estimator().estimate();
  const InputResult result = r->fusion.push(std::move(input));
  take_calibration(*r);
  if (!result.accepted) {
    counts_.reject(kind + ".", *result.rejection);
    return std::nullopt;
  }
  counts_.accept();
  if (beacon) r->beacons_used.insert(*beacon);
  return correction_output(robot_id, *r, before);
}

void LocalizerCore::on_initial_pose(const std::string& robot_id, StampNs stamp_ns, const Pose2& pose,
                                    const Cov3& covariance) {
  Robot* r = robot(robot_id, "initial_pose");
  if (!r) return;
  const InputResult result = r->fusion.reset(stamp_ns, pose, covariance);
  if (!result.accepted) {
    counts_.reject("initial_pose.", *result.rejection);
    return;
  }
  counts_.accept();
}

std::vector<Estimator::Association> LocalizerCore::take_associations(const std::string& robot_id) {
  auto it = robots_.find(robot_id);
  return it == robots_.end() ? std::vector<Estimator::Association>{} : it->second.fusion.take_associations();
}

// One sample far (over a second) behind the time line is refused as out of order; a second that
// continues from it (within 200 ms) shows the clock itself went back. Samples a little out of
// order (two writers for one robot, a misconfiguration) are refused without a restart.
bool LocalizerCore::clock_jumped_back(Robot& r, const OdometrySample& odometry) {
  const auto newest_ns = r.fusion.newest_odometry_ns();
  if (!newest_ns || !older_than(odometry.stamp_ns, *newest_ns, kClockJumpMinNs)) return false;
  const auto& candidate = r.jump_candidate_ns;
  if (candidate && odometry.stamp_ns > *candidate &&
      !older_than(*candidate, odometry.stamp_ns, kClockJumpConfirmationNs)) {
    return true;
  }
  r.jump_candidate_ns = odometry.stamp_ns;
  return false;
}

void LocalizerCore::on_ranges_silent(const std::string& robot_id) {
  auto it = robots_.find(robot_id);
  if (it != robots_.end()) it->second.ranges_silent = true;
}

void LocalizerCore::on_odometry_deadline_missed(const std::string& robot_id) {
  auto it = robots_.find(robot_id);
  if (it != robots_.end() && !it->second.odometry_silent()) ++it->second.odometry_deadlines_missed;
}

std::vector<std::string> LocalizerCore::odometry_silent_robots() const {
  std::vector<std::string> ids;
  for (const auto& [id, r] : robots_) {
    if (r.odometry_silent()) ids.push_back(id);
  }
  return ids;
}

std::vector<std::string> LocalizerCore::robot_ids() const {
  std::vector<std::string> ids;
  ids.reserve(robots_.size());
  for (const auto& [id, r] : robots_) ids.push_back(id);
  return ids;
}

std::uint64_t LocalizerCore::replays() const {
  std::uint64_t n = 0;
  for (const auto& [id, r] : robots_) n += r.fusion.replays();
  return n;
}

namespace {
int severity(PoseStatus s) {
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
}
}  // namespace

PoseStatus LocalizerCore::Robot::status() const {
  const PoseStatus estimator_status = fusion.estimator().status();
  // Silent ranges make a good pose degraded at once, rather than after the estimator's own
  // 1 s of data time without a fused range.
  // Silent odometry: the pose stands still while the robot may move.
  if ((ranges_silent || odometry_silent()) && severity(estimator_status) < severity(PoseStatus::kDegraded))
    return PoseStatus::kDegraded;
  return estimator_status;
}

std::optional<StartupWait> LocalizerCore::startup_wait(const std::string& robot_id) const {
  const auto it = robots_.find(robot_id);
  if (it == robots_.end()) return std::nullopt;
  return it->second.fusion.estimator().startup_wait();
}

std::optional<FiringPlan> LocalizerCore::firing_plan(const std::string& robot_id) const {
  const Estimator* e = estimator(robot_id);
  if (!e || map_.size() == 0) return std::nullopt;
  const std::optional<PoseEstimate> pose = e->estimate();
  // Only a trusted pose narrows the firing: a degraded one (no correction for a second, ranges
  // that contradict it) may be off by more than its covariance says.
  if (!pose || pose->status != PoseStatus::kOk || !publishable(*pose)) return std::nullopt;
  return FiringPlan{pose->stamp_ns, plan_firing(map_, config_.receivers, pose->pose_map_base, pose->covariance)};
}

StartupSummary LocalizerCore::startup_summary() const {
  StartupSummary s;
  for (const auto& [id, r] : robots_) {  // by robot id
    const std::optional<StartupWait> wait = r.fusion.estimator().startup_wait();
    if (!wait) continue;
    if (s.empty()) {
      s.first_robot = id;
      s.first_wait = *wait;
    }
    ++s.robots_by_condition[wait->condition];
  }
  return s;
}

std::string StartupSummary::describe() const {
  std::size_t total = 0;
  std::string conditions;
  for (const auto& [condition, n] : robots_by_condition) {
    total += n;
    conditions +=
        (conditions.empty() ? "" : ", ") + std::string(to_string(condition)) + " " + std::to_string(n);
  }
  if (total == 0) return {};
  return std::to_string(total) + " initializing: " + conditions + " (robot " + first_robot + ": " +
         first_wait.describe() + ")";
}

PoseStatus LocalizerCore::worst_status() const {
  PoseStatus worst = PoseStatus::kOk;
  for (const auto& [id, r] : robots_) {
    if (severity(r.status()) > severity(worst)) worst = r.status();
  }
  return worst;
}

}  // namespace beaconloc
