#include "range_ekf.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <set>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/solvers/range_pose_solver.hpp"

namespace beaconloc {

namespace {
// Arrivals of one firing at the receivers of one robot: within the time sound takes to cross the
// robot (0.4 m / 343 m/s = 1.2 ms), far less than the 200 ms between two firings.
constexpr StampNs kSameFiringNs = 20 * kNsPerMillisecond;
}  // namespace

RangeEkfParameters RangeEkfParameters::from(const EstimatorConfig& c) {
  RangeEkfParameters p;
  p.nis_gate = c.parameter("nis_gate", p.nis_gate);
  p.init_window_s = c.parameter("init_window_s", p.init_window_s);
  p.init_min_beacons = static_cast<int>(c.parameter("init_min_beacons", p.init_min_beacons));
  p.init_min_ranges = static_cast<int>(c.parameter("init_min_ranges", p.init_min_ranges));
  p.init_min_beacon_spread_m = c.parameter("init_min_beacon_spread_m", p.init_min_beacon_spread_m);
  p.max_odometry_gap_s = c.parameter("max_odometry_gap_s", p.max_odometry_gap_s);
  p.reinitialize_after_gated =
      static_cast<int>(c.parameter("reinitialize_after_gated", p.reinitialize_after_gated));
  p.max_range_age_s = c.parameter("max_range_age_s", p.max_range_age_s);
  p.init_max_position_sigma_m = c.parameter("init_max_position_sigma_m", p.init_max_position_sigma_m);
  p.init_max_yaw_sigma_rad = c.parameter("init_max_yaw_sigma_rad", p.init_max_yaw_sigma_rad);
  p.init_retry_interval_s = c.parameter("init_retry_interval_s", p.init_retry_interval_s);
  p.init_outlier_gate_sigma = c.parameter("init_outlier_gate_sigma", p.init_outlier_gate_sigma);
  return p;
}

RangeEkf::RangeEkf(const EstimatorConfig& config)
    : receivers_(config.receivers),
      params_(RangeEkfParameters::from(config)),
      timeline_(params_.max_odometry_gap_s) {}

InputResult RangeEkf::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = timeline_.advance(o);
  if (!step.integrate) return step.result;
  const double dt_s = step.dt_s;
  odom_pose_ = predict_diff_drive(odom_pose_, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps,
                                  o.wheel_base_m, dt_s)
                   .pose;
  if (initialized_) {
    const DiffDrivePrediction p = predict_diff_drive(ekf_.state(), o.wheel_velocity_right_mps,
                                                     o.wheel_velocity_left_mps, o.wheel_base_m, dt_s);
    const Eigen::Matrix2d u = o.wheel_velocity_covariance +
                              params_.wheel_velocity_variance_floor_m2ps2 * Eigen::Matrix2d::Identity();
    // Eq. 16: P = J_f,x P J_f,x^T + J_f,u U J_f,u^T.
    ekf_.predict(p.pose, p.jacobian_pose, p.jacobian_wheels * u * p.jacobian_wheels.transpose());
  }
  return InputResult::ok();
}

InputResult RangeEkf::update(const RangeMeasurement& r) {
  if (const InputResult checked = check_range(r, map_, receivers_.size()); !checked.accepted) return checked;
  if (timeline_.last_stamp_ns() &&
      r.stamp_ns < *timeline_.last_stamp_ns() - s_to_ns(params_.max_range_age_s)) {
    return InputResult::rejected("stale_range");
  }

  // Every good range joins the window a global fix is computed from.
  window_.push_back({r, odom_pose_});
  while (!window_.empty() && window_.front().range.stamp_ns < r.stamp_ns - s_to_ns(params_.init_window_s)) {
    window_.pop_front();
  }
  if (!initialized_) {
    try_initialize();
    return InputResult::ok();
  }
  return fuse(r);
}

// The range is fused at the filter's current time (the newest odometry stamp); pushed in stamp
// order, the pulse arrived within one odometry period of it (<= 10 ms, 3.4 mm at 0.34 m/s). The
// localizer pushes in stamp order however late a range arrives (core/out_of_sequence_fusion).
InputResult RangeEkf::fuse(const RangeMeasurement& r) {
  const Beacon& beacon = *map_.find(r.beacon_id);
  const RangePrediction p = predict_range(ekf_.state(), receivers_.receivers_base_m[r.receiver_id],
                                          receivers_.receiver_height_m, beacon.position_map_m);
  const Eigen::Matrix<double, 1, 1> innovation(r.range_m - p.range_m);
  const Eigen::Matrix<double, 1, 1> noise(r.variance_m2);
  const UpdateResult result = ekf_.update<1>(innovation, p.jacobian_pose, noise, params_.nis_gate);
  switch (result.outcome) {
    case UpdateOutcome::kApplied:
      ekf_.mutable_state().z() = wrap_angle_rad(ekf_.state().z());
      consecutive_gated_ = 0;
      last_correction_stamp_ns_ = std::max(r.stamp_ns, timeline_.last_stamp_ns().value_or(r.stamp_ns));
      return InputResult::ok();
    case UpdateOutcome::kSingularInnovation:
      return InputResult::rejected("singular_innovation");
    case UpdateOutcome::kGated:
      break;
  }
  if (++consecutive_gated_ >= params_.reinitialize_after_gated) {
    // The filter no longer agrees with the beacons: start again from a global fix.
    initialized_ = false;
    consecutive_gated_ = 0;
    try_initialize();
  }
  return InputResult::rejected("gated_nis");
}

void RangeEkf::try_initialize() {
  // The multi-start solve costs ~1 ms: not more often than init_retry_interval_s of data time.
  const StampNs now_ns = window_.back().range.stamp_ns;
  if (last_init_attempt_ns_ && now_ns - *last_init_attempt_ns_ < s_to_ns(params_.init_retry_interval_s))
    return;
  std::set<std::uint32_t> beacons;
  for (const auto& b : window_) beacons.insert(b.range.beacon_id);
  if (static_cast<int>(beacons.size()) < params_.init_min_beacons) return;
  // Spread of the beacons across their principal axis (smallest eigenvalue of their scatter).
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (auto id : beacons) mean += map_.find(id)->position_map_m.head<2>();
  mean /= static_cast<double>(beacons.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (auto id : beacons) {
    const Eigen::Vector2d d = map_.find(id)->position_map_m.head<2>() - mean;
    scatter += d * d.transpose() / static_cast<double>(beacons.size());
  }
  if (Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues().minCoeff() <
      params_.init_min_beacon_spread_m * params_.init_min_beacon_spread_m) {
    return;
  }
  // Echoes, screened by geometry alone: two receivers d apart hearing one firing measure ranges
  // that differ by at most d (triangle inequality); an echo's path is longer, so of a pair that
  // differs by more, the longer range is the echo.
  std::vector<bool> echo(window_.size(), false);
  for (std::size_t i = 0; i < window_.size(); ++i) {
    for (std::size_t j = i + 1; j < window_.size(); ++j) {
      const RangeMeasurement& a = window_[i].range;
      const RangeMeasurement& b = window_[j].range;
      if (a.beacon_id != b.beacon_id || a.receiver_id == b.receiver_id ||
          std::abs(a.stamp_ns - b.stamp_ns) > kSameFiringNs) {
        continue;
      }
      const double baseline_m =
          (receivers_.receivers_base_m[a.receiver_id] - receivers_.receivers_base_m[b.receiver_id]).norm();
      if (std::abs(a.range_m - b.range_m) > baseline_m + 3.0 * std::sqrt(a.variance_m2 + b.variance_m2)) {
        echo[a.range_m > b.range_m ? i : j] = true;
      }
    }
  }

  std::vector<RangeObservation> observations;
  for (std::size_t k = 0; k < window_.size(); ++k) {
    if (echo[k]) continue;
    const BufferedRange& b = window_[k];
    // Where the receiver was, in the frame of the robot now (dead-reckoned odometry).
    const Pose2 then_in_now = between(odom_pose_, b.odom_pose_at_range);
    const double travelled_m = then_in_now.head<2>().norm();
    RangeObservation o;
    o.receiver_solve_frame_m = transform_point(then_in_now, receivers_.receivers_base_m[b.range.receiver_id]);
    o.receiver_z_m = receivers_.receiver_height_m;
    o.beacon_map_m = map_.find(b.range.beacon_id)->position_map_m;
    o.range_m = b.range.range_m;
    // Odometry drift over the window adds to the range noise: 2 % of the distance travelled.
    o.variance_m2 = b.range.variance_m2 + std::pow(0.02 * travelled_m, 2);
    observations.push_back(o);
  }
  // Echoes (a reflection's longer path) in the window would pull the fix off the pose: drop the
  // ranges the fix cannot explain (core/solvers/range_pose_solver.hpp).
  RangePoseSolverOptions solver;
  solver.outlier_gate_sigma = params_.init_outlier_gate_sigma;
  // Three unknowns: with fewer than init_min_ranges ranges an echo among them fits as well as the
  // truth does; wait for redundancy.
  if (static_cast<int>(observations.size()) < params_.init_min_ranges) return;
  last_init_attempt_ns_ = now_ns;
  const RangePoseSolution fix = solve_pose_from_ranges(observations, solver);
  if (!fix.ok) return;
  if (std::sqrt(fix.covariance(0, 0) + fix.covariance(1, 1)) > params_.init_max_position_sigma_m ||
      std::sqrt(fix.covariance(2, 2)) > params_.init_max_yaw_sigma_rad) {
    return;  // geometry too weak yet; wait for more beacons
  }
  // The fix ignores the correlation the shared odometry introduces: inflate it.
  const Cov3 p0 = 4.0 * fix.covariance + Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal().toDenseMatrix();
  ekf_.reset(fix.pose, p0);
  initialized_ = true;
  consecutive_gated_ = 0;
  last_correction_stamp_ns_ = std::max(window_.back().range.stamp_ns,
                                       timeline_.last_stamp_ns().value_or(window_.back().range.stamp_ns));
}

InputResult RangeEkf::reset(StampNs stamp_ns, const Pose2& pose, const Cov3& covariance) {
  if (const InputResult checked = check_initial_pose(pose, covariance); !checked.accepted) return checked;
  ekf_.reset(pose, covariance);  // the global fix is not needed: the pose was given
  initialized_ = true;
  consecutive_gated_ = 0;
  last_correction_stamp_ns_ = timeline_.last_stamp_ns().value_or(stamp_ns);
  return InputResult::ok();
}

std::optional<PoseEstimate> RangeEkf::estimate() const {
  if (!initialized_ || !timeline_.last_stamp_ns()) return std::nullopt;
  PoseEstimate e;
  e.stamp_ns = *timeline_.last_stamp_ns();
  e.pose_map_base = ekf_.state();
  e.covariance = ekf_.covariance();
  e.status = status();
  return e;
}

PoseStatus RangeEkf::status() const {
  if (!initialized_) return PoseStatus::kInitializing;
  return staleness_.classify(timeline_.last_stamp_ns().value_or(last_correction_stamp_ns_),
                             last_correction_stamp_ns_);
}

namespace {
BEACONLOC_REGISTER_ESTIMATOR("range_ekf",
                             "EKF on [x, y, yaw]: odometry prediction, one update per range, NIS gating",
                             [](const EstimatorConfig& config) {
                               return std::make_unique<RangeEkf>(config);
                             });
}  // namespace

}  // namespace beaconloc
