#include "range_ekf.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "beaconloc/core/chi_square.hpp"
#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/solvers/range_pose_solver.hpp"

namespace beaconloc {

namespace {
// One pose is preferred to another (a global fix to its mirror image, a fix to a suspect
// filter pose) when it fits the same ranges better by this much weighted squared residual.
// Whichever of two poses is the robot's, noise makes the other fit better by T with probability
// at most Phi(-sqrt(T)) (the cost difference is N(-d^2, 4 d^2) for predictions d sigma apart;
// worst at d^2 = T): 0.05 % at chi-square 1 dof 99.9 %.
constexpr double kPoseMarginChiSquare = kChiSquare999OneDof;
}  // namespace

RangeEkfParameters RangeEkfParameters::from(const EstimatorConfig& c) {
  namespace ranges = parameter_ranges;
  ParameterReader in(c, "range_ekf");
  RangeEkfParameters p;
  p.nis_gate = in.real("nis_gate", p.nis_gate, ranges::kChiSquareGate);
  p.init_window_s =
      in.real("init_window_s", p.init_window_s, ParameterRange::above(0.0, RangeEkfParameters::kMaxInitWindowS));
  p.init_min_beacons = in.count("init_min_beacons", p.init_min_beacons, 1, 100);
  p.init_min_ranges =
      in.count("init_min_ranges", p.init_min_ranges, static_cast<int>(kRangePoseMinObservations), 1000);
  p.max_odometry_gap_s = in.real("max_odometry_gap_s", p.max_odometry_gap_s, ranges::kDataDurationS);
  p.reinitialize_after_gated = in.count("reinitialize_after_gated", p.reinitialize_after_gated, 1, 1000);
  p.max_range_age_s = in.real("max_range_age_s", p.max_range_age_s, ranges::kDataDurationS);
  p.init_max_position_sigma_m =
      in.real("init_max_position_sigma_m", p.init_max_position_sigma_m, ranges::kPositionSigmaM);
  p.init_max_position_sigma_ranges = in.real("init_max_position_sigma_ranges", p.init_max_position_sigma_ranges,
                                             ParameterRange::closed(0.0, 100.0));
  p.init_max_yaw_sigma_rad =
      in.real("init_max_yaw_sigma_rad", p.init_max_yaw_sigma_rad, ranges::kHeadingSigmaRad);
  p.init_retry_interval_s = in.real("init_retry_interval_s", p.init_retry_interval_s,
                                    ParameterRange::closed(0.0, ranges::kDataDurationS.max));
  p.init_outlier_gate_sigma =
      in.real("init_outlier_gate_sigma", p.init_outlier_gate_sigma, ParameterRange::closed(0.0, 100.0));
  p.divergence_window_ranges = in.count("divergence_window_ranges", p.divergence_window_ranges, 1, 1000);
  p.divergence_gated_ranges =
      in.count("divergence_gated_ranges", p.divergence_gated_ranges, 1, p.divergence_window_ranges);
  p.range_calibration = in.count("range_calibration", p.range_calibration, 0, 2);
  p.learn_range_noise = in.flag("learn_range_noise", p.learn_range_noise);
  p.range_scale_sigma = in.real("range_scale_sigma", p.range_scale_sigma,
                                ParameterRange::above(0.0, RangeCalibrationStates::kMaxScaleSigma));
  p.range_bias_sigma_m = in.real("range_bias_sigma_m", p.range_bias_sigma_m, ParameterRange::above(0.0, 100.0));
  in.finish();
  return p;
}

RangeEkf::RangeEkf(const EstimatorConfig& config) : RangeEkf(config, RangeEkfParameters::from(config)) {}

RangeEkf::RangeEkf(const EstimatorConfig& config, const RangeEkfParameters& params)
    : EstimatorBase(params.max_odometry_gap_s),
      receivers_(config.receivers),
      params_(params),
      calibration_(static_cast<RangeCalibrationMode>(params.range_calibration), params.range_scale_sigma,
                   params.range_bias_sigma_m) {
  waiting_for_ = {StartupCondition::kTooFewBeacons, 0.0, static_cast<double>(params_.init_min_beacons), {}};
}

InputResult RangeEkf::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = advance(o);
  // The time line now stands at this sample (integrated, its anchor, or re-anchored after a
  // gap): its wheel speeds are the robot's newest.
  if (step.result.accepted || step.result.rejection == Rejection::kOdometryGap) last_odometry_ = o;
  if (!step.integrate) return step.result;
  const double dt_s = step.dt_s;
  odom_pose_ = predict_diff_drive(odom_pose_, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps,
                                  o.wheel_base_m, dt_s)
                   .pose;
  if (has_pose()) {
    const DiffDriveMotion motion(o.wheel_base_m,
                                 o.wheel_velocity_covariance +
                                     params_.wheel_velocity_variance_floor_m2ps2 * Eigen::Matrix2d::Identity());
    // Eq. 14, 16: P = J_f,x P J_f,x^T + J_f,u U J_f,u^T.
    const PredictResult predicted = with_filter([&](auto& filter) {
      return filter.predict(motion, Eigen::Vector2d(o.wheel_velocity_right_mps, o.wheel_velocity_left_mps), dt_s);
    });
    if (!predicted.applied()) return InputResult::of(predicted.outcome);
  }
  return InputResult::ok();
}

InputResult RangeEkf::update(const RangeMeasurement& r) {
  if (const InputResult checked = check_range(r, map(), receivers_.size()); !checked.accepted) return checked;
  if (now_ns() &&
      r.stamp_ns < *now_ns() - s_to_ns(params_.max_range_age_s)) {
    return InputResult::rejected(Rejection::kStaleRange);
  }

  // Every good range joins the window a global fix is computed from.
  const Pose2 odom_pose_at_range = odom_pose_at(r.stamp_ns);
  window_.push_back({r, odom_pose_at_range});
  const auto older_than = [&](double age_s) { return window_.front().range.stamp_ns < r.stamp_ns - s_to_ns(age_s); };
  while (!window_.empty() &&
         (window_.size() > RangeEkfParameters::kMaxWindowRanges || older_than(RangeEkfParameters::kMaxInitWindowS) ||
          (older_than(params_.init_window_s) &&
           window_.size() > static_cast<std::size_t>(params_.init_min_ranges)))) {
    window_.pop_front();
  }
  if (!has_pose()) {
    try_initialize();
    return InputResult::ok();
  }
  return fuse(r, odom_pose_at_range);
}

Pose2 RangeEkf::odom_pose_at(StampNs stamp_ns) const {
  if (!last_odometry_ || !now_ns()) return odom_pose_;
  const double lag_s = ns_to_s(stamp_ns - *now_ns());
  if (std::abs(lag_s) > odometry_gap_limit_s()) return odom_pose_;
  const OdometrySample& o = *last_odometry_;
  return predict_diff_drive(odom_pose_, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps, o.wheel_base_m, lag_s)
      .pose;
}

// The range is fused at the filter's current time (the newest odometry stamp, now_ns()); pushed
// in stamp order (the localizer does, however late a range arrives: core/out_of_sequence_fusion),
// its pulse arrived after that odometry and before the next one: up to one odometry period
// later (10 ms at 100 Hz, 0.2 s on a recording with 5 Hz odometry, 0.2 m at 1 m/s). The receiver
// is taken where the robot was at the range's stamp: moved, in the frame of the pose now, along
// the newest wheel speeds over the lag (eq. 14 with dT = the lag). The lag's own uncertainty
// (the speeds' noise times the lag) is left out: 1 mm at 100 Hz.
InputResult RangeEkf::fuse(const RangeMeasurement& r, const Pose2& odom_pose_at_range) {
  const Beacon& beacon = *map().find(r.beacon_id);
  const Pose2 then_in_now = between(odom_pose_, odom_pose_at_range);
  const Eigen::Vector2d receiver_now_m = transform_point(then_in_now, receivers_.receivers_base_m[r.receiver_id]);
  const RangeCalibrationIndex calibration =
      calibration_.enabled() ? calibration_of(r.beacon_id) : RangeCalibrationIndex{};
  const auto model_with = [&](double variance_m2) {
    return RangeModel(receiver_now_m, receivers_.receiver_height_m, beacon.position_map_m, variance_m2, PoseIndex{},
                      calibration);
  };
  const RangeModel model = model_with(r.variance_m2);
  double variance_m2 = r.variance_m2;
  if (params_.learn_range_noise) {
    // The range's noise as learnt so far (RangeNoiseScale), then this innovation learnt from,
    // unless the ranges make the pose suspect: a filter that is off would teach a sigma too large.
    variance_m2 = noise_scale_.variance_m2(r.variance_m2);
    if (!suspect_) {
      const auto prior = with_filter(
          [&](const auto& filter) { return filter.prior_innovation(model, RangeModel::Vector(r.range_m)); });
      if (prior) noise_scale_.learn(prior->innovation(0), prior->state_covariance(0, 0), r.variance_m2);
    }
  }
  const UpdateResult result = with_filter([&](auto& filter) {
    return filter.update(model_with(variance_m2), RangeModel::Vector(r.range_m), params_.nis_gate);
  });
  static_assert(RangeModel::kSize == 1, "log 2 pi is the constant of a 1-D Gaussian");
  if (result.outcome == FilterOutcome::kApplied || result.outcome == FilterOutcome::kGated) {
    const double nis = result.outcome == FilterOutcome::kGated ? params_.nis_gate : result.nis;
    innovation_nll_sum_ += 0.5 * (nis + result.log_det_s + std::log(2.0 * M_PI));
    ++innovations_;
  }
  switch (result.outcome) {
    case FilterOutcome::kApplied:
      consecutive_gated_ = 0;
      if (calibration_.enabled() && !calibration_.plausible(calibrating_.state())) {
        calibration_to_prior(true);
        ++calibration_resets_;
      }
      corrected(std::max(r.stamp_ns, now_ns().value_or(r.stamp_ns)));
      watch_divergence({false, result.nis});
      return InputResult::ok();
    case FilterOutcome::kGated:
      break;
    default:
      return InputResult::of(result.outcome);
  }
  ++consecutive_gated_;
  watch_divergence({true, result.nis});
  if (has_pose() && consecutive_gated_ >= params_.reinitialize_after_gated) {
    // The filter no longer agrees with the beacons: start again from a global fix, and let the
    // calibration (which may be what went wrong) be learnt again from its values now.
    forget_pose();
    if (calibration_.enabled()) calibration_to_prior(false);
    consecutive_gated_ = 0;
    try_initialize();
  }
  return InputResult::rejected(Rejection::kGatedNis);
}

// The recent ranges judge the pose: a run of gated ranges, or applied ones fitting worse than
// chi-square allows, make it suspect (degraded); a global fix from the window of ranges settles
// it, restarting the filter when the fix contradicts it.
void RangeEkf::watch_divergence(const RangeOutcome& outcome) {
  recent_.push_back(outcome);
  while (static_cast<int>(recent_.size()) > params_.divergence_window_ranges) recent_.pop_front();
  int gated = 0, applied = 0;
  double applied_nis = 0.0;
  for (const RangeOutcome& o : recent_) {
    if (o.gated) {
      ++gated;
    } else {
      ++applied;
      applied_nis += o.nis;
    }
  }
  const bool full = static_cast<int>(recent_.size()) == params_.divergence_window_ranges;
  suspect_ = gated >= params_.divergence_gated_ranges ||
             (full && applied > 0 && applied_nis > chi_square_quantile_999(applied));
  if (!suspect_) return;
  const StampNs newest_range_ns = window_.back().range.stamp_ns;
  if (!attempt_due(newest_range_ns)) return;
  const WindowFix fix = window_fix();
  if (fix.solved) last_init_attempt_ns_ = newest_range_ns;
  if (!fix.ok) return;  // nothing to settle it with yet: the pose stays degraded
  // Contradicted: the fix lies outside the pose's uncertainty and explains the window's ranges
  // better by the margin (echoes capped, so that they weigh on both alike).
  const PoseBelief belief = pose_belief();
  const Eigen::Vector3d d = pose_difference(fix.pose, belief.pose_map_base);
  const double cap_sigma = params_.init_outlier_gate_sigma > 0.0 ? params_.init_outlier_gate_sigma
                                                                 : std::numeric_limits<double>::infinity();
  const double fix_cost = truncated_range_cost(fix.observations, fix.pose, cap_sigma);
  const double pose_cost = truncated_range_cost(fix.observations, belief.pose_map_base, cap_sigma);
  const double margin = kPoseMarginChiSquare * fix.variance_factor;
  if (d.dot((belief.covariance + fix.covariance).ldlt().solve(d)) > kChiSquare999ThreeDof &&
      pose_cost - fix_cost > margin) {
    start_from(fix, std::max(newest_range_ns, now_ns().value_or(newest_range_ns)));
    ++divergence_reinitializations_;
  }
  recent_.clear();  // explained: by a wrong pose now replaced, or by outliers the fix agrees on
  suspect_ = false;
}

bool RangeEkf::attempt_due(StampNs newest_range_ns) const {
  // The multi-start solve costs ~1 ms: not more often than init_retry_interval_s of data time.
  return !last_init_attempt_ns_ || newest_range_ns - *last_init_attempt_ns_ >= s_to_ns(params_.init_retry_interval_s);
}

void RangeEkf::try_initialize() {
  const StampNs newest_range_ns = window_.back().range.stamp_ns;
  if (!attempt_due(newest_range_ns)) return;
  calibrate_window_beacons();
  const WindowFix fix = window_fix();
  if (fix.solved) last_init_attempt_ns_ = newest_range_ns;
  if (!fix.ok) {
    waiting_for_ = fix.why_not;
    return;
  }
  start_from(fix, std::max(newest_range_ns, now_ns().value_or(newest_range_ns)));
}

void RangeEkf::calibrate_window_beacons() {
  if (!calibration_.enabled()) return;
  for (const BufferedRange& b : window_) {
    if (map().find(b.range.beacon_id)) calibration_of(b.range.beacon_id);
  }
}

void RangeEkf::start_from(const WindowFix& fix, StampNs correction_stamp_ns) {
  place(fix.pose, fix.covariance);
  if (calibration_.enabled() && fix.calibration_sensitivity.cols() == calibrating_.state().size() - 3) {
    // The fix read its ranges back with the calibration as it stands: its error moves with the
    // calibration's, P_pose = P_fix + J P_cal J^T and P_pose,cal = J P_cal (first order), so
    // that the ranges that make the calibration observable correct the pose with it. (J is
    // taken with the solver's C, P_fix with the fix's inflated one: conservative.)
    Eigen::MatrixXd p = calibrating_.covariance();
    const Eigen::Index n = p.rows() - 3;
    const Eigen::MatrixXd& j = fix.calibration_sensitivity;
    const Eigen::MatrixXd cross = j * p.bottomRightCorner(n, n);
    p.topLeftCorner<3, 3>() += cross * j.transpose();
    p.topRightCorner(3, n) = cross;
    p.bottomLeftCorner(n, 3) = cross.transpose();
    // T diag(P_fix, P_cal) T^T with T = [I J; 0 I]: positive semi-definite. A non-finite J
    // (refused by reset) leaves the fix uncorrelated with the calibration.
    calibrating_.reset(calibrating_.state(), symmetrized(p));
  }
  start(correction_stamp_ns);
}

bool RangeEkf::place(const Pose2& pose, const Cov3& covariance) {
  // A checked pose (check_initial_pose) or a global fix. The calibration is the sensor's, not
  // the pose's: it stays, its correlation with the old pose dropped.
  if (calibration_.enabled()) {
    Eigen::VectorXd x = calibrating_.state();
    Eigen::MatrixXd p = calibrating_.covariance();
    x.head<3>() = pose;
    p.topRows<3>().setZero();
    p.leftCols<3>().setZero();
    p.topLeftCorner<3, 3>() = covariance;
    calibrating_.reset(x, p);
  } else {
    ekf_.reset(pose, covariance);
  }
  consecutive_gated_ = 0;
  recent_.clear();
  suspect_ = false;
  return true;
}

RangeEkf::WindowFix RangeEkf::window_fix() const {
  WindowFix out;
  std::set<std::uint32_t> beacons;
  for (const auto& b : window_) {
    if (map().find(b.range.beacon_id)) beacons.insert(b.range.beacon_id);
  }
  if (static_cast<int>(beacons.size()) < params_.init_min_beacons) {
    out.why_not = {StartupCondition::kTooFewBeacons,
                   static_cast<double>(beacons.size()),
                   static_cast<double>(params_.init_min_beacons),
                   {}};
    return out;
  }
  // Echoes, screened by geometry alone (ranges_of_one_firing_agree). O(n^2) over a window of at most
  // kMaxWindowRanges (not in strict stamp order: ranges a little ahead of the odometry are
  // taken as they arrive).
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
      if (!ranges_of_one_firing_agree(a.range_m, b.range_m, baseline_m, a.variance_m2 + b.variance_m2)) {
        echo[a.range_m > b.range_m ? i : j] = true;
      }
    }
  }

  std::vector<RangeObservation> observations;
  std::vector<std::uint32_t> observed_beacons;  // beside observations
  std::vector<double> range_variances_m2;       // as the calibration reads them, without the drift's share
  for (std::size_t k = 0; k < window_.size(); ++k) {
    const BufferedRange& b = window_[k];
    const Beacon* beacon = map().find(b.range.beacon_id);
    if (echo[k] || !beacon) continue;
    // Where the receiver was, in the frame of the robot now (dead-reckoned odometry).
    const Pose2 then_in_now = between(odom_pose_, b.odom_pose_at_range);
    const double travelled_m = then_in_now.head<2>().norm();
    RangeObservation o;
    o.receiver_solve_frame_m = transform_point(then_in_now, receivers_.receivers_base_m[b.range.receiver_id]);
    o.receiver_z_m = receivers_.receiver_height_m;
    o.beacon_map_m = beacon->position_map_m;
    // The range as the calibration learnt so far reads it (as it is, without calibration).
    const RangeCalibrationStates::Corrected range = calibration_.corrected(
        b.range.beacon_id, b.range.range_m, b.range.variance_m2, calibrating_.state());
    o.range_m = range.range_m;
    // Odometry drift over the window adds to the range noise: 2 % of the distance travelled.
    o.variance_m2 = range.variance_m2 + std::pow(0.02 * travelled_m, 2);
    range_variances_m2.push_back(range.variance_m2);
    observations.push_back(o);
    observed_beacons.push_back(b.range.beacon_id);
  }
  // Three unknowns: with fewer than init_min_ranges ranges an echo among them fits as well as the
  // truth does; wait for redundancy.
  if (static_cast<int>(observations.size()) < params_.init_min_ranges) {
    out.why_not = {StartupCondition::kTooFewRanges,
                   static_cast<double>(observations.size()),
                   static_cast<double>(params_.init_min_ranges),
                   {}};
    return out;
  }
  std::nth_element(range_variances_m2.begin(), range_variances_m2.begin() + range_variances_m2.size() / 2,
                   range_variances_m2.end());
  const double median_range_sigma_m = std::sqrt(range_variances_m2[range_variances_m2.size() / 2]);
  // Echoes (a reflection's longer path) in the window would pull the fix off the pose: drop the
  // ranges the fix cannot explain (core/solvers/range_pose_solver.hpp).
  RangePoseSolverOptions solver;
  solver.outlier_gate_sigma = params_.init_outlier_gate_sigma;
  out.solved = true;
  const RangePoseSolution fix = solve_pose_from_ranges(observations, solver);
  if (!fix.ok) {
    out.why_not = {StartupCondition::kFixFailed, 0.0, 0.0, fix.failure};
    return out;
  }
  // The ranges moved by odometry fit worse than their noise says when the window's motion
  // drifted (a fast turn): cost differences are then as much larger, and so is the margin.
  const double dof = static_cast<double>(observations.size() - fix.outliers) - 3.0;
  out.variance_factor = std::max(1.0, fix.weighted_residual_rms * fix.weighted_residual_rms *
                                          static_cast<double>(observations.size() - fix.outliers) / dof);
  if (fix.mirror_cost_margin < kPoseMarginChiSquare * out.variance_factor) {
    // Beacons on one line, and receivers that cannot tell its two sides apart.
    out.why_not = {StartupCondition::kMirrorAmbiguous,
                   fix.mirror_cost_margin,
                   kPoseMarginChiSquare * out.variance_factor,
                   {}};
    return out;
  }
  const double position_sigma_m = std::sqrt(fix.covariance(0, 0) + fix.covariance(1, 1));
  const double max_position_sigma_m =
      std::max(params_.init_max_position_sigma_m,
               std::min(params_.init_max_position_sigma_ranges * median_range_sigma_m,
                        parameter_ranges::kPositionSigmaM.max));
  if (position_sigma_m > max_position_sigma_m) {  // geometry too weak yet
    out.why_not = {StartupCondition::kPositionTooUncertain, position_sigma_m, max_position_sigma_m, {}};
    return out;
  }
  const double yaw_sigma_rad = std::sqrt(fix.covariance(2, 2));
  if (yaw_sigma_rad > params_.init_max_yaw_sigma_rad) {
    out.why_not = {StartupCondition::kHeadingTooUncertain, yaw_sigma_rad, params_.init_max_yaw_sigma_rad, {}};
    return out;
  }
  out.ok = true;
  out.pose = fix.pose;
  if (calibration_.enabled()) {
    // d pose / d r_i = C H_i^T / var_i at the fix (C = (H^T R^-1 H)^-1), over the ranges the fix
    // kept; a range read back as d = (r - b) / s moves by -d / s with the scale, -1 / s with the bias.
    const Eigen::VectorXd& x = calibrating_.state();
    out.calibration_sensitivity = Eigen::MatrixXd::Zero(3, x.size() - 3);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const RangeObservation& o = observations[i];
      const RangePrediction h = predict_range(fix.pose, o.receiver_solve_frame_m, o.receiver_z_m, o.beacon_map_m);
      const double residual_sigma = std::abs(o.range_m - h.range_m) / std::sqrt(o.variance_m2);
      if (params_.init_outlier_gate_sigma > 0.0 && residual_sigma > params_.init_outlier_gate_sigma) continue;
      const auto at = calibration_.index(observed_beacons[i]);
      if (!at) continue;
      const Eigen::Vector3d a = fix.covariance * h.jacobian_pose.transpose() / o.variance_m2;
      const double scale = x(*at->scale);
      out.calibration_sensitivity.col(*at->scale - 3) -= a * (o.range_m / scale);
      out.calibration_sensitivity.col(*at->bias_m - 3) -= a / scale;
    }
  }
  out.observations = std::move(observations);
  // The fix ignores the correlation the shared odometry introduces: inflate it.
  out.covariance = 4.0 * fix.covariance + Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal().toDenseMatrix();
  return out;
}

EstimatorBase::PoseBelief RangeEkf::pose_belief() const {
  return with_filter([](const auto& filter) {
    return PoseBelief{filter.state().template head<3>(), filter.covariance().template topLeftCorner<3, 3>()};
  });
}

RangeCalibrationIndex RangeEkf::calibration_of(std::uint32_t beacon_id) {
  if (const auto known = calibration_.index(beacon_id)) return *known;
  Eigen::VectorXd x = calibrating_.state();
  Eigen::MatrixXd p = calibrating_.covariance();
  const std::optional<RangeCalibrationIndex> added = calibration_.add(beacon_id, x, p);
  if (!added) return {};
  calibrating_ = Ekf<Eigen::Dynamic>(StateSpace<Eigen::Dynamic>::with_pose({}, x.size()));
  calibrating_.reset(x, p);  // the old belief, finite, with a pair at its prior: accepted
  return *added;
}

void RangeEkf::calibration_to_prior(bool values) {
  Eigen::VectorXd x = calibrating_.state();
  Eigen::MatrixXd p = calibrating_.covariance();
  calibration_.to_prior(x, p, values);
  calibrating_.reset(x, p);
}

std::vector<Estimator::StateValue> RangeEkf::state_values() const {
  std::vector<StateValue> out;
  if (innovations_ > 0) {
    out.push_back({"range_innovation_nll_nats", innovation_nll_sum_ / static_cast<double>(innovations_), 0.0});
  }
  if (params_.learn_range_noise) out.push_back({"range_noise_scale", noise_scale_.scale(), 0.0});
  if (!calibration_.enabled()) return out;
  const std::vector<StateValue> calibration = calibration_.values(calibrating_.state(), calibrating_.covariance());
  out.insert(out.end(), calibration.begin(), calibration.end());
  out.push_back({"range_calibration_resets", static_cast<double>(calibration_resets_), 0.0});
  out.push_back({"range_calibration_uncalibrated_beacons", static_cast<double>(calibration_.uncalibrated_beacons()), 0.0});
  return out;
}

namespace {
BEACONLOC_REGISTER_ESTIMATOR("range_ekf",
                             "EKF on [x, y, yaw]: odometry prediction, one update per range, NIS gating",
                             "default.yaml",
                             [](const EstimatorConfig& config) {
                               return std::make_unique<RangeEkf>(config);
                             });
}  // namespace

}  // namespace beaconloc
