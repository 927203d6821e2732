#include "scan/scan_estimator.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "beaconloc/core/chi_square.hpp"
#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"

namespace beaconloc::scan {
namespace {

// A beacon's range rate is taken from a previous range at most this old (seed003_scan.yaml's
// group cycle is 0.76 s: three cycles, two of them missed, and some margin).
constexpr StampNs kRangeRateWindowNs = 3 * kNsPerSecond;
// More ranges in one group's epoch than any ULPS has beacons (the paper's have 4-5): a flood,
// refused before a Gauss-Newton fix over them costs O(n^3) per iteration.
constexpr std::size_t kMaxEpochRanges = 64;
// A frame relocates after this many GRULPS fixes in a row contradict it (one may be an echo's),
// and stops relocating after as many agree.
constexpr int kFixesToRelocate = 2;

}  // namespace

ScanParameters ScanParameters::from(const EstimatorConfig& c) {
  namespace ranges = parameter_ranges;
  ParameterReader in(c, "scan");
  ScanParameters p;
  // Sec. 3.4: "we have implemented three representative filters": 0 EKF, 1 UKF, 2 H-infinity.
  p.filter.kind = static_cast<FilterKind>(in.count("filter", 0, 0, 2));
  p.filter.h_infinity_theta =
      in.real("h_infinity_theta", p.filter.h_infinity_theta, ParameterRange::closed(0.0, 1e6));
  p.geometry = in.flag("hyperbolic", false) ? Geometry::kHyperbolic : Geometry::kSpherical;
  p.transform = in.flag("numerical_transform", false) ? TransformMethod::kNumerical : TransformMethod::kAnalytic;
  p.d_min_m = in.real("d_min_m", p.d_min_m, ParameterRange::above(0.0, 100.0));
  p.numerical_points = in.count("numerical_points", p.numerical_points, 2, 1000);
  p.start.heading_baseline_m = in.real("heading_baseline_m", p.start.heading_baseline_m, ParameterRange::above(0.0, 100.0));
  p.epoch_window_s = in.real("epoch_window_s", p.epoch_window_s, ranges::kDataDurationS);
  p.overlap_end_s = in.real("overlap_end_s", p.overlap_end_s, ranges::kDataDurationS);
  p.max_odometry_gap_s = in.real("max_odometry_gap_s", p.max_odometry_gap_s, ranges::kDataDurationS);
  p.inverse_trajectory = in.flag("inverse_trajectory", p.inverse_trajectory);
  p.inverse_after_s = in.real("inverse_after_s", p.inverse_after_s, ParameterRange::above(0.0, 600.0));
  in.finish();
  return p;
}

ScanEstimator::ScanEstimator(const EstimatorConfig& config) : ScanEstimator(config, ScanParameters::from(config)) {}

ScanEstimator::ScanEstimator(const EstimatorConfig& config, const ScanParameters& params)
    : EstimatorBase(params.max_odometry_gap_s),
      config_(config),
      receivers_(config.receivers),
      params_(params),
      global_(params) {
  // Sec. 3.2: one receiver (Sec. 5: a microphone on the robot); its fixes are its own position.
  if (receivers_.size() != 1) throw std::invalid_argument("scan: the robot must have exactly one receiver (seed 003)");
  waiting_for_ = {StartupCondition::kTooFewBeacons, 0.0, static_cast<double>(ranges_for_a_fix(params_.geometry)), {}};
}

// Everything measured against the beacons goes with the map they were measured against (the
// localizer makes a new estimator for a new map; this holds for any caller).
void ScanEstimator::set_beacon_map(const BeaconMap& map) {
  EstimatorBase::set_beacon_map(map);
  if (has_pose()) forget_pose();
  global_ = Frame(params_);
  local_.clear();
  for (const LocalBeacon& b : map.local_beacons()) local_.try_emplace(b.group, params_);
  calibrated_.clear();
  calibration_ = {};
  calibration_changed_ = false;  // nothing the site learnt is withdrawn: the map's change is the localizer's to handle
  open_epochs_.clear();
  last_range_.clear();
  log_.clear();
  log_full_ = false;
  last_grulps_correction_ns_.reset();
  back_in_grulps_since_ns_.reset();
  calibrated_since_grulps_ = 0;
  calibrated_correction_m2_.setZero();  // the old map's calibrated groups no longer correct the pose
  waiting_for_ = {StartupCondition::kTooFewBeacons, 0.0, static_cast<double>(ranges_for_a_fix(params_.geometry)), {}};
}

bool ScanEstimator::use_calibration(const BeaconCalibration& c) {
  if (!check_calibration(c).ok() || calibration_fitting(c, map()).groups.size() != c.groups.size()) return false;
  for (const GroupCalibration& g : c.groups) {
    const auto held = std::find_if(calibration_.groups.begin(), calibration_.groups.end(),
                                   [&](const GroupCalibration& h) { return h.group == g.group; });
    if (held != calibration_.groups.end() && BeaconCalibration{{*held}} == BeaconCalibration{{g}}) continue;
    local_.erase(g.group);
    calibrate(g.group, g);
  }
  return true;
}

std::optional<BeaconCalibration> ScanEstimator::take_calibration_update() {
  if (!calibration_changed_) return std::nullopt;
  calibration_changed_ = false;
  return calibration_;
}

bool ScanEstimator::pairs_possible(StampNs now_ns) const {
  // Corrected within overlap_end_s: a window of one group cycle (1 s) left so few pairs on seed
  // 003 that the calibrations were worse (0.214-0.351 m against 0.221-0.250 m on seeds 1-4).
  return global_.started && !global_.relocating && recently(global_.last_correction_ns, now_ns);
}

Cov3 ScanEstimator::global_covariance() const {
  Cov3 p = global_.filter.covariance();
  const std::optional<StampNs> now = now_ns();
  if (now && !recently(last_grulps_correction_ns_, *now)) p.topLeftCorner<2, 2>() += calibrated_correction_m2_;
  return p;
}

Eigen::Matrix2d ScanEstimator::calibrated_group_covariance(std::uint32_t beacon_id) const {
  const LocalBeacon* local = map().find_local(beacon_id);
  Eigen::Matrix2d largest = Eigen::Matrix2d::Zero();
  if (!local) return largest;
  // The group's calibration as it stands (a recalibrated group's beacons only).
  for (const GroupCalibration& g : calibration_.groups) {
    if (g.group != local->group) continue;
    for (const CalibratedBeacon& b : g.beacons) {
      if (b.covariance_m2.trace() > largest.trace()) largest = b.covariance_m2;
    }
  }
  return largest;
}

bool ScanEstimator::recently(const std::optional<StampNs>& stamp_ns, StampNs now_ns) const {
  return stamp_ns && now_ns - *stamp_ns <= s_to_ns(params_.overlap_end_s);
}

std::optional<ScanEstimator::FrameBeacon> ScanEstimator::global_beacon(std::uint32_t id) const {
  if (const Beacon* b = map().find(id)) return FrameBeacon{b->position_map_m, Eigen::Matrix2d::Zero()};
  if (auto it = calibrated_.find(id); it != calibrated_.end()) {
    return FrameBeacon{it->second.position_map_m, it->second.covariance_m2};
  }
  return std::nullopt;
}

InputResult ScanEstimator::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = advance(o);
  if (!step.integrate) return step.result;
  const double floor = params_.wheel_velocity_variance_floor_m2ps2;
  odometry_pose_ =
      predict_diff_drive(odometry_pose_, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps, o.wheel_base_m, step.dt_s)
          .pose;
  odometry_integrated_ns_ += s_to_ns(step.dt_s);
  const auto advance_frame = [&](Frame& f) {
    if (f.started && f.relocating) {
      if (const PredictResult r = f.start.predict(o, step.dt_s, floor); !r.applied()) return r;
    }
    return f.started ? f.filter.predict(o, step.dt_s, floor) : f.start.predict(o, step.dt_s, floor);
  };
  const PredictResult global_step = advance_frame(global_);
  // A group's frame that cannot be moved starts again (its next fixes); the map pose goes on.
  for (auto& [group, local] : local_) {
    if (!advance_frame(local.frame).applied()) local.frame = Frame(params_);
  }
  if (!global_step.applied()) return InputResult::of(global_step.outcome);
  record(o);
  const StampNs now = *now_ns();
  close_epochs(now, false);
  finish_overlaps(now);
  maybe_run_inverse_trajectory(now, false);
  return InputResult::ok();
}

ScanEstimator::Compared ScanEstimator::compare(const RangeMeasurement& r, const RangeSample& predecessor) const {
  const StampNs dt_ns = r.stamp_ns - predecessor.stamp_ns;
  if (dt_ns <= 0 || dt_ns > kRangeRateWindowNs) return {};
  // What the receiver moved: the odometry's displacement, 5 % of it for the odometry's error, and
  // 4 sigma of the two ranges. Time between the two the odometry did not integrate (a gap, or
  // before its first sample): the receiver may have moved as fast as any robot then.
  const Eigen::Vector2d& rx = receivers_.receivers_base_m[0];
  const double moved_m =
      (transform_point(odometry_pose_, rx) - transform_point(predecessor.odometry_pose, rx)).norm();
  const StampNs unseen_ns = dt_ns - (odometry_integrated_ns_ - predecessor.integrated_ns);
  const double unseen_m = unseen_ns > s_to_ns(params_.epoch_window_s) ? kMaxWheelSpeedMps * ns_to_s(unseen_ns) : 0.0;
  const double allowed_m = 1.05 * moved_m + unseen_m + 4.0 * std::sqrt(r.variance_m2 + predecessor.variance_m2);
  const double change_m = r.range_m - predecessor.range_m;
  if (std::abs(change_m) <= allowed_m) return {RangeChange::kWithinMotion, change_m / ns_to_s(dt_ns)};
  return {change_m > 0.0 ? RangeChange::kLonger : RangeChange::kShorter, 0.0};
}

InputResult ScanEstimator::update(const RangeMeasurement& r) {
  if (InputResult numbers = check_range_numbers(r); !numbers.accepted) return numbers;
  if (r.beacon_id == kBeaconUnidentified) return InputResult::rejected(Rejection::kUnassociatedRange);
  if (map().empty()) return InputResult::rejected(Rejection::kNoBeaconMap);
  const Beacon* known = map().find(r.beacon_id);
  const LocalBeacon* local = map().find_local(r.beacon_id);
  if (!known && !local) return InputResult::rejected(Rejection::kUnknownBeacon);
  if (r.receiver_id >= receivers_.size()) return InputResult::rejected(Rejection::kUnknownReceiver);
  if (now_ns() && r.stamp_ns < *now_ns() - kMeasurementHorizonNs) return InputResult::rejected(Rejection::kStaleRange);
  // Pushed in stamp order, a range is at most an odometry period ahead of the newest odometry; one
  // further ahead would poison its beacon's range rate for every later fix.
  if (now_ns() && r.stamp_ns > *now_ns() + s_to_ns(params_.epoch_window_s)) {
    return InputResult::rejected(Rejection::kAheadOfOdometry);
  }
  const auto last = last_range_.find(r.beacon_id);  // this beacon's previous ranges, if any
  if (last != last_range_.end() && last->second.newest_ns == r.stamp_ns) {
    return InputResult::rejected(Rejection::kDuplicateRange);
  }

  // A range cannot change by more than the receiver moved (compare): a larger change is an
  // echo's (its extra path is 0.3 m or more), and its "rate" would move the range wrongly. An
  // echo is longer than the direct path: this range, when it grew too much (kept out of the
  // rates, the previous one stays the reference); the previous, when it shrank too much, and
  // then the rate is taken from the one before that, when it is within the motion.
  std::optional<double> rate_mps;
  bool an_echo = false;          // longer than the beacon's previous range allows
  bool after_an_echo = false;    // shorter: the previous range was an echo
  if (last != last_range_.end()) {
    const Compared latest = compare(r, last->second.latest);
    an_echo = latest.change == RangeChange::kLonger;
    after_an_echo = latest.change == RangeChange::kShorter;
    if (latest.change == RangeChange::kWithinMotion) rate_mps = latest.rate_mps;
    if (after_an_echo && last->second.before) {
      const Compared before = compare(r, *last->second.before);
      if (before.change == RangeChange::kWithinMotion) rate_mps = before.rate_mps;
    }
  }
  // Longer than its beacon's previous range by more than the receiver moved: an echo, in no
  // epoch, no fix and no filter (a filter's gate alone lets it through a calibrated beacon's wide
  // variance), and not the next range's predecessor; its stamp is kept for the duplicate check.
  if (an_echo) {
    last->second.newest_ns = std::max(last->second.newest_ns, r.stamp_ns);  // an echo has a predecessor
    return InputResult::rejected(Rejection::kLongerThanTheReceiverMoved);
  }

  // Every good range joins its group's epoch (the fixes and the hyperbolic updates are made of them).
  const std::uint32_t group = known ? known->group : local->group;
  // A frame's correction is stamped with the range (up to an odometry period after the newest
  // odometry), so that an epoch's first range counts as inside it.
  const StampNs now = std::max(now_ns().value_or(r.stamp_ns), r.stamp_ns);
  auto open = open_epochs_.find(group);
  if (open != open_epochs_.end()) {
    const Epoch& e = open->second;
    const bool repeated = std::any_of(e.ranges.begin(), e.ranges.end(),
                                      [&](const EpochEntry& x) { return x.beacon_id == r.beacon_id; });
    if (repeated || r.stamp_ns - e.ranges.front().stamp_ns > s_to_ns(params_.epoch_window_s)) {
      const Epoch done = e;
      open_epochs_.erase(open);
      process_epoch(done);
    }
  }
  Epoch& epoch = open_epochs_[group];
  epoch.group = group;
  if (epoch.ranges.size() >= kMaxEpochRanges) return InputResult::rejected(Rejection::kTooManyRangesInEpoch);
  record(r);
  // The next range's predecessor: this one, when newer than the reference (an older one, pushed
  // out of order, is not).
  LastRange& ref = last_range_[r.beacon_id];
  if (r.stamp_ns > ref.latest.stamp_ns || ref.newest_ns == 0) {
    if (ref.newest_ns != 0 && !after_an_echo) ref.before = ref.latest;  // an echo is no one's predecessor
    ref.latest = {r.stamp_ns, r.range_m, r.variance_m2, odometry_pose_, odometry_integrated_ns_};
  }
  ref.newest_ns = std::max(ref.newest_ns, r.stamp_ns);
  epoch.ranges.push_back({r.beacon_id, r.range_m, r.variance_m2, odometry_pose_, r.stamp_ns, rate_mps});

  if (params_.geometry == Geometry::kHyperbolic) return InputResult::ok();  // fused with its epoch
  // Spherical: a range updates its frame's filter at once (frame_filter.hpp).
  if (const std::optional<FrameBeacon> b = global_beacon(r.beacon_id)) {
    if (!global_.started) return InputResult::ok();  // kept for the first fixes
    const UpdateResult u = [&] {
      Eigen::Matrix2d beacon_covariance = b->covariance_m2;
      const Eigen::Vector2d line = b->position_m.head<2>() - global_.filter.pose().head<2>();
      const double extra = r.range_m > 0.0 ? line.dot(beacon_covariance * line) / (r.range_m * r.range_m) : 0.0;
      return global_.filter.update_range(receivers_.receivers_base_m[0], receivers_.receiver_height_m, b->position_m,
                                         r.range_m, r.variance_m2 + extra);
    }();
    if (!u.applied()) return InputResult::of(u.outcome);
    global_corrected(now);
    if (known) note_grulps_correction(now);
    else calibrated_correction_m2_ = calibrated_group_covariance(r.beacon_id);
    return InputResult::ok();
  }
  const auto uncalibrated = local_.find(group);  // uncalibrated: only its own frame uses it
  if (uncalibrated == local_.end()) return InputResult::rejected(Rejection::kUncalibratedBeacon);
  LocalGroup& l = uncalibrated->second;
  if (!l.frame.started) return InputResult::ok();
  const UpdateResult u = l.frame.filter.update_range(receivers_.receivers_base_m[0], receivers_.receiver_height_m,
                                                     local->position_group_m, r.range_m, r.variance_m2);
  if (!u.applied()) return InputResult::of(u.outcome);
  l.frame.last_correction_ns = now;
  return InputResult::ok();
}

void ScanEstimator::close_epochs(StampNs now_ns, bool all) {
  for (auto it = open_epochs_.begin(); it != open_epochs_.end();) {
    if (all || now_ns - it->second.ranges.front().stamp_ns > s_to_ns(params_.epoch_window_s)) {
      const Epoch done = it->second;
      it = open_epochs_.erase(it);
      process_epoch(done);
    } else {
      ++it;
    }
  }
}

void ScanEstimator::process_epoch(const Epoch& epoch) {
  const StampNs now = now_ns().value_or(epoch.ranges.back().stamp_ns);
  auto local = local_.find(epoch.group);
  if (local == local_.end()) {  // a GRULPS, or an LRULPS calibrated already: the global frame's
    const bool grulps = map().find(epoch.ranges.front().beacon_id) != nullptr;
    if (!global_.started) {
      start_frame(global_, epoch, true);
      return;
    }
    if (params_.geometry == Geometry::kHyperbolic && fuse_epoch(global_, epoch, true)) {
      global_corrected(now);
      if (grulps) {
        note_grulps_correction(now);
      } else {
        calibrated_correction_m2_ = calibrated_group_covariance(epoch.ranges.front().beacon_id);
      }
    }
    check_fix(epoch, grulps);
    return;
  }
  LocalGroup& l = local->second;
  if (!l.frame.started) {
    // Sec. 3.3: the group's first positions are its Gauss-Newton fixes; they are points of its
    // local track as much as the filter's later ones, and a pair with the global track when that
    // is tracking (the overlap starts where the robot first hears the group, not once the frame
    // has its heading: a metre later).
    // A fix is where the receiver was at the epoch's last range, not where it is now (the epoch
    // closes later): it is paired with the global track's point then (seen from the global pose
    // through the odometry), or the lag of every fix (and of no filter point) shrinks the local
    // track against the global (a scale of 0.99 on seed 003).
    const std::optional<GroupFix> fix = start_frame(l.frame, epoch, false);
    if (fix && pairs_possible(now)) {
      const Pose2& then = epoch.ranges.back().odometry_pose;
      add_pair(l, fix->position_m, compose(global_.filter.pose(), between(odometry_pose_, then)));
    }
    return;
  }
  if (params_.geometry == Geometry::kHyperbolic && fuse_epoch(l.frame, epoch, false)) l.frame.last_correction_ns = now;
  // The overlap (Sec. 3.5): this group's frame corrected within this epoch and the global frame
  // by a group it knows, lately; both filters are at the same instant (the same odometry).
  const bool local_now = l.frame.last_correction_ns && *l.frame.last_correction_ns >= epoch.ranges.front().stamp_ns;
  if (local_now && pairs_possible(now)) {
    add_pair(l, transform_point(l.frame.filter.pose(), receivers_.receivers_base_m[0]), global_.filter.pose());
  }
}

std::optional<GroupFix> ScanEstimator::fix_of(const Epoch& epoch, bool global) {
  GroupMeasurements m;
  m.geometry = params_.geometry;
  m.receiver_z_m = receivers_.receiver_height_m;
  double variance_sum = 0.0;
  const StampNs reference_ns = epoch.ranges.back().stamp_ns;
  std::vector<const EpochEntry*> used;  // beside m's ranges
  for (const EpochEntry& e : epoch.ranges) {
    if (!e.range_rate_mps) continue;  // cannot be brought to the epoch's last instant (see the header)
    if (global) {
      const std::optional<FrameBeacon> b = global_beacon(e.beacon_id);
      if (!b) continue;
      m.beacons_m.push_back(b->position_m);
    } else {
      const LocalBeacon* b = map().find_local(e.beacon_id);
      if (!b) continue;
      m.beacons_m.push_back(b->position_group_m);
    }
    m.ranges_m.push_back(e.range_m + *e.range_rate_mps * ns_to_s(reference_ns - e.stamp_ns));
    used.push_back(&e);
    variance_sum += e.variance_m2;
  }
  const bool first_pose = global && !global_.started;
  const std::size_t needed = ranges_for_a_fix(params_.geometry);
  if (m.beacons_m.size() < needed) {
    if (first_pose) {
      waiting_for_ = {StartupCondition::kTooFewBeacons, static_cast<double>(m.beacons_m.size()),
                      static_cast<double>(needed), {}};
    }
    return std::nullopt;
  }
  m.range_sigma_m = std::sqrt(variance_sum / static_cast<double>(m.ranges_m.size()));
  const GroupFixWithoutAnEcho solved = solve_group_fix_without_an_echo(m);
  if (solved.left_out) echo_left_out_of_fix(*used[*solved.left_out]);
  const GroupFix& fix = solved.fix;
  if (!fix.ok()) {
    if (first_pose) waiting_for_ = {StartupCondition::kFixFailed, 0.0, 0.0, to_string(fix.failure)};
    return std::nullopt;
  }
  return fix;
}

// A range a fix found to be an echo, counted once (an epoch may be fixed twice: checked against
// the global filter, then starting it again).
void ScanEstimator::echo_left_out_of_fix(const EpochEntry& echo) {
  const std::pair<std::uint32_t, StampNs> which{echo.beacon_id, echo.stamp_ns};
  if (which == last_echo_left_out_) return;
  last_echo_left_out_ = which;
  ++echoes_left_out_of_fixes_;
}

std::optional<GroupFix> ScanEstimator::start_frame(Frame& frame, const Epoch& epoch, bool global) {
  const std::optional<GroupFix> fix = fix_of(epoch, global);
  if (!fix) return std::nullopt;
  const std::optional<FrameBelief> belief = frame.start.add_fix(*fix);
  if (!belief) {
    if (global && !global_.started) {
      waiting_for_ = {StartupCondition::kNeedsMotion, frame.start.displacement_m(), params_.start.heading_baseline_m, {}};
    }
    return fix;
  }
  // The fixes are the receiver's positions: the base is the receiver's offset behind it.
  Pose2 pose = belief->pose_frame_base;
  pose.head<2>() -= transform_point(Pose2(0.0, 0.0, pose.z()), receivers_.receivers_base_m[0]);
  if (frame.filter.start(pose, belief->covariance) != FilterOutcome::kApplied) return std::nullopt;
  frame.started = true;
  frame.relocating = false;
  const StampNs now = now_ns().value_or(epoch.ranges.back().stamp_ns);
  frame.last_correction_ns = now;
  if (global) start(now);
  return fix;
}

// A correction after a coast longer than the staleness policy's degraded_after: the filter may
// have drifted beyond its covariance, and a range that happens to fit says little. The pose stays
// suspect until a fix of a known group agrees with it.
void ScanEstimator::global_corrected(StampNs now_ns) {
  if (global_.last_correction_ns && now_ns - *global_.last_correction_ns > StalenessPolicy{}.degraded_after_ns) {
    global_.unconfirmed = true;
  }
  global_.last_correction_ns = now_ns;
  corrected(now_ns);
}

void ScanEstimator::check_fix(const Epoch& epoch, bool grulps) {
  const std::optional<GroupFix> fix = fix_of(epoch, true);
  if (!fix) return;
  // The filter where the fix is: at the epoch's last range, through the odometry since.
  const Pose2 then = compose(global_.filter.pose(), between(odometry_pose_, epoch.ranges.back().odometry_pose));
  const Eigen::Vector2d d = fix->position_m - transform_point(then, receivers_.receivers_base_m[0]);
  const Eigen::LDLT<Eigen::Matrix2d> s(fix->covariance_m2 + global_.filter.covariance().topLeftCorner<2, 2>());
  const bool disagrees = s.info() != Eigen::Success || !(d.dot(s.solve(d)) <= chi_square_quantile_999(2));
  if (!disagrees) global_.unconfirmed = false;
  // Only a GRULPS (the map's own beacons) is trusted over the filter: a calibrated group that
  // disagrees leaves the pose unconfirmed, no more.
  if (!grulps) return;
  global_.fixes_in_a_row = disagrees == (global_.fixes_in_a_row >= 0) ? global_.fixes_in_a_row + (disagrees ? 1 : -1)
                                                                       : (disagrees ? 1 : -1);
  if (!global_.relocating && global_.fixes_in_a_row >= kFixesToRelocate) {
    global_.relocating = true;
    global_.start = FrameStart(params_.start);
  } else if (global_.relocating && global_.fixes_in_a_row <= -kFixesToRelocate) {
    global_.relocating = false;  // the filter agrees again: the disagreement was the fixes'
    return;
  }
  // While relocating, every fix goes to the new start; its belief replaces the filter's.
  if (global_.relocating) start_frame(global_, epoch, true);
}

bool ScanEstimator::fuse_epoch(Frame& frame, const Epoch& epoch, bool global) {
  std::vector<EpochRange> ranges;
  double variance = 0.0;
  for (const EpochEntry& e : epoch.ranges) {
    Eigen::Vector3d position;
    double extra = 0.0;
    if (global) {
      const std::optional<FrameBeacon> b = global_beacon(e.beacon_id);
      if (!b) continue;
      position = b->position_m;
      const Eigen::Vector2d line = position.head<2>() - frame.filter.pose().head<2>();
      extra = line.dot(b->covariance_m2 * line) / (e.range_m * e.range_m);
    } else {
      const LocalBeacon* b = map().find_local(e.beacon_id);
      if (!b) continue;
      position = b->position_group_m;
    }
    ranges.push_back({position, e.range_m, e.odometry_pose});
    variance = std::max(variance, e.variance_m2 + extra);  // eq. 19 takes one sigma for all
  }
  if (ranges.size() < 2) return false;  // not one difference
  const UpdateResult u = frame.filter.update_differences(receivers_.receivers_base_m[0], receivers_.receiver_height_m,
                                                         ranges, odometry_pose_, variance);
  return u.applied();
}

// The receiver's position in both frames (a fix is the receiver's, not the base's).
void ScanEstimator::add_pair(LocalGroup& l, const Eigen::Vector2d& local_receiver_m, const Pose2& global_pose) {
  const PointPair pair{local_receiver_m, transform_point(global_pose, receivers_.receivers_base_m[0])};
  l.average.add(pair);
  if (l.track.size() < AnalyticAverage::kMaxTrackPairs) l.track.push_back(pair);
  l.covariance.add(pair.global_m, global_covariance());
  ++l.pairs;
}

std::optional<GroupCalibration> ScanEstimator::transform_of(std::uint32_t group, const LocalGroup& l,
                                                            StampNs now_ns) const {
  if (l.pairs == 0) return std::nullopt;
  const TransformFit fit =
      params_.transform == TransformMethod::kAnalytic
          ? l.average.average()
          : numerical_similarity(spread_points(l.track, params_.d_min_m, static_cast<std::size_t>(params_.numerical_points)));
  if (!fit.transform) return std::nullopt;
  GroupCalibration g;
  g.group = group;
  g.stamp_ns = now_ns;
  g.transform = fit.transform->t_c;
  g.mean_error_m = fit.mean_error_m;
  // The fit's residual adds to the global frame's error at the pairs (calibration_covariance.hpp).
  const Eigen::Matrix2d residual = 0.5 * fit.mean_error_m * fit.mean_error_m * Eigen::Matrix2d::Identity();
  for (const LocalBeacon& b : map().local_beacons()) {
    if (b.group != group) continue;
    CalibratedBeacon c;
    c.id = b.id;
    c.position_map_m << fit.transform->apply(b.position_group_m.head<2>()), b.position_group_m.z();  // eq. 42-43
    c.covariance_m2 = l.covariance.at(c.position_map_m.head<2>()) + residual;
    g.beacons.push_back(c);
  }
  BeaconCalibration one;
  one.groups.push_back(g);
  if (!check_calibration(one).ok()) return std::nullopt;  // a transform no frame can have (a scale of 3)
  return g;
}

std::optional<GroupCalibration> ScanEstimator::provisional_calibration(std::uint32_t group) const {
  const auto it = local_.find(group);
  if (it == local_.end() || !now_ns()) return std::nullopt;
  return transform_of(group, it->second, *now_ns());
}

void ScanEstimator::finish_overlaps(StampNs now_ns) {
  if (recently(global_.last_correction_ns, now_ns)) return;  // inside a known group's coverage still
  for (auto it = local_.begin(); it != local_.end();) {
    LocalGroup& l = it->second;
    if (l.pairs == 0) {
      ++it;
      continue;
    }
    const std::optional<GroupCalibration> g = transform_of(it->first, l, now_ns);
    if (!g) {  // the overlap gave no transform (too short): wait for another
      l.average = AnalyticAverage(params_.d_min_m);
      l.track.clear();
      l.covariance.clear();
      l.pairs = 0;
      ++it;
      continue;
    }
    const std::uint32_t group = it->first;
    it = local_.erase(it);
    calibrate(group, *g);
    ++calibrated_since_grulps_;
  }
}

// A group's calibration in, or in place of the one it had.
void ScanEstimator::calibrate(std::uint32_t group, const GroupCalibration& g) {
  for (const CalibratedBeacon& b : g.beacons) calibrated_[b.id] = b;
  calibration_changed_ = true;
  for (GroupCalibration& old : calibration_.groups) {
    if (old.group == group) {
      old = g;
      return;
    }
  }
  calibration_.groups.push_back(g);
}

void ScanEstimator::record(const RecordedInput& input) {
  if (!params_.inverse_trajectory || log_full_) return;
  if (log_.size() >= params_.max_recorded_inputs) {
    log_full_ = true;  // this leg gets no backwards drive
    log_.clear();
    return;
  }
  log_.push_back(input);
}

void ScanEstimator::note_grulps_correction(StampNs now_ns) {
  // Back from outside every GRULPS, with groups calibrated on the way: the backwards drive will
  // start here once the robot has been here for inverse_after_s.
  const bool was_away = !last_grulps_correction_ns_ || now_ns - *last_grulps_correction_ns_ > s_to_ns(params_.overlap_end_s);
  if (was_away && last_grulps_correction_ns_ && calibrated_since_grulps_ > 0 && !back_in_grulps_since_ns_) {
    back_in_grulps_since_ns_ = now_ns;
  }
  last_grulps_correction_ns_ = now_ns;
  // Nothing calibrated or under way since the robot was last here: the leg starts now, and what
  // was kept before it (time spent inside a GRULPS) is dropped.
  const bool overlap_under_way =
      std::any_of(local_.begin(), local_.end(), [](const auto& l) { return l.second.pairs > 0; });
  if (calibrated_since_grulps_ == 0 && !overlap_under_way) {
    log_.clear();
    log_full_ = false;
  }
}

void ScanEstimator::maybe_run_inverse_trajectory(StampNs now_ns, bool now_or_never) {
  if (!back_in_grulps_since_ns_) return;
  if (!now_or_never && now_ns - *back_in_grulps_since_ns_ < s_to_ns(params_.inverse_after_s)) return;
  back_in_grulps_since_ns_.reset();
  calibrated_since_grulps_ = 0;
  if (!params_.inverse_trajectory || log_full_) {
    ++inverse_passes_skipped_;
  } else {
    ++inverse_passes_;
    BeaconCalibration backwards = inverse_trajectory_calibration(config_, map(), log_);
    for (GroupCalibration& b : backwards.groups) {
      b.stamp_ns = now_ns;  // found now (the backwards drive's own clock runs from its start)
      const auto forwards = std::find_if(calibration_.groups.begin(), calibration_.groups.end(),
                                         [&](const GroupCalibration& f) { return f.group == b.group; });
      const bool better = forwards == calibration_.groups.end() ||
                          b.beacons.front().covariance_m2.trace() < forwards->beacons.front().covariance_m2.trace();
      if (better) {
        local_.erase(b.group);
        calibrate(b.group, b);
      }
    }
  }
  // The next leg starts here.
  log_.clear();
  log_full_ = false;
}

void ScanEstimator::finish() {
  if (!now_ns()) return;
  close_epochs(*now_ns(), true);
  for (auto it = local_.begin(); it != local_.end();) {
    const std::optional<GroupCalibration> g = transform_of(it->first, it->second, *now_ns());
    if (!g) {
      ++it;
      continue;
    }
    const std::uint32_t group = it->first;
    it = local_.erase(it);
    calibrate(group, *g);
  }
  maybe_run_inverse_trajectory(*now_ns(), true);
}

std::vector<Estimator::StateValue> ScanEstimator::state_values() const {
  return {{"calibrated_groups", static_cast<double>(calibration_.groups.size()), 0.0},
          {"inverse_passes", static_cast<double>(inverse_passes_), 0.0},
          {"inverse_passes_skipped", static_cast<double>(inverse_passes_skipped_), 0.0},
          {"echoes_left_out_of_fixes", static_cast<double>(echoes_left_out_of_fixes_), 0.0}};
}

BEACONLOC_REGISTER_ESTIMATOR("scan",
                             "seed 003 SCAN: one filter per frame (EKF, UKF or H-infinity; spherical or hyperbolic), "
                             "locally referenced beacon groups calibrated while driving (Sec. 3.5)",
                             "seed003_scan.yaml",
                             [](const EstimatorConfig& c) { return std::make_unique<ScanEstimator>(c); });

}  // namespace beaconloc::scan
