#include "duhl_estimator.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/linear_model.hpp"
#include "beaconloc/core/models/pose_observation_model.hpp"

namespace beaconloc::duhl {
namespace {

ReceiverRing ring_of(const EstimatorConfig& config) {
  // The UHL needs the three receivers of eq. 1 on one circle; take its radius from the robot.
  ReceiverRing ring;
  if (!config.receivers.receivers_base_m.empty()) ring.radius_m = config.receivers.receivers_base_m[0].norm();
  ring.height_m = config.receivers.receiver_height_m;
  return ring;
}

bool three_on_a_circle(const EstimatorConfig& config) {
  const ReceiverRing ring = ring_of(config);
  if (config.receivers.size() != 3 || !(ring.radius_m > 0.0)) return false;
  for (int l = 0; l < 3; ++l) {
    if ((config.receivers.receivers_base_m[l] - ring.receiver(l)).norm() > 1e-6) return false;
  }
  return true;
}

UhlOptions uhl_options(const EstimatorConfig& config, ParameterReader& in) {
  UhlOptions o;
  const ReceiverRing ring = ring_of(config);
  o.receiver_radius_m = ring.radius_m;
  o.receiver_height_m = ring.height_m;
  // A distance from the Txs' line, within a room.
  o.collinear_threshold_m =
      in.real("uhl_collinear_threshold_m", o.collinear_threshold_m, ParameterRange::above(0.0, 10.0));
  return o;
}

}  // namespace

Cov3 uhl_observation_covariance(const std::vector<TxDistances>& txs, const UhlSolution& solution,
                                const std::vector<DistanceCov>& covariances, const UhlOptions& options) {
  // J_z,q: analytic where Table I took the DM heading and the IMR multilateration, otherwise
  // by central differences through the UHL.
  const std::optional<UhlJacobian> analytic = uhl_jacobian(txs, solution, options);
  const UhlJacobian j = analytic ? *analytic : uhl_jacobian_numeric(txs, options);
  Cov3 r = Cov3::Zero();
  for (std::size_t i = 0; i < txs.size(); ++i) {
    const Eigen::Matrix3d ji = j.middleCols<3>(3 * static_cast<Eigen::Index>(i));
    r += ji * covariances[i] * ji.transpose();
  }
  return r;
}

DuhlParameters DuhlParameters::from(const EstimatorConfig& c) {
  namespace ranges = parameter_ranges;
  ParameterReader in(c, "duhl");
  DuhlParameters p;
  p.uhl = uhl_options(c, in);
  // A distance variance: positive, at most (1 m)^2 (the paper's sigma_dd is 1 cm).
  p.discard_variance_m2 =
      in.real("discard_variance_m2", p.discard_variance_m2, ParameterRange::above(0.0, 1.0));
  p.observation_nis_gate = in.real("observation_nis_gate", p.observation_nis_gate, ranges::kChiSquareGate);
  p.max_odometry_gap_s = in.real("max_odometry_gap_s", p.max_odometry_gap_s, ranges::kDataDurationS);
  p.reinitialize_after_gated = in.count("reinitialize_after_gated", p.reinitialize_after_gated, 0, 1000);
  p.observation_covariance_as_printed =
      in.flag("observation_covariance_as_printed", p.observation_covariance_as_printed);
  p.distance_innovation_gate =
      in.real("distance_innovation_gate", p.distance_innovation_gate, ranges::kChiSquareGateOrOff);
  p.range_pose_gate = in.real("range_pose_gate", p.range_pose_gate, ranges::kChiSquareGateOrOff);
  p.suspect_after_gated_ranges = in.count("suspect_after_gated_ranges", p.suspect_after_gated_ranges, 1, 1000);
  p.lost_after_gated_ranges = in.count("lost_after_gated_ranges", p.lost_after_gated_ranges, 1, 1000);
  p.start_residual_gate_sigma =
      in.real("start_residual_gate_sigma", p.start_residual_gate_sigma, ParameterRange::above(0.0, 100.0));
  in.finish();
  return p;
}

Duhl::Duhl(const EstimatorConfig& config) : Duhl(config, DuhlParameters::from(config)) {}

Duhl::Duhl(const EstimatorConfig& config, const DuhlParameters& params)
    : EstimatorBase(params.max_odometry_gap_s), ring_(ring_of(config)), params_(params) {
  if (!three_on_a_circle(config)) {
    throw std::invalid_argument(
        "duhl needs three receivers on a circle at 0, 120, 240 degrees (seed 000 eq. 1)");
  }
}

InputResult Duhl::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = advance(o);
  if (!step.integrate) return step.result;
  const Eigen::Matrix2d u =
      o.wheel_velocity_covariance + params_.wheel_velocity_variance_floor_m2ps2 * Eigen::Matrix2d::Identity();
  if (has_pose()) {  // eq. 14, 16
    const PredictResult predicted = ekf_.predict(
        DiffDriveMotion(o.wheel_base_m, u), Eigen::Vector2d(o.wheel_velocity_right_mps, o.wheel_velocity_left_mps),
        step.dt_s);
    if (!predicted.applied()) return InputResult::of(predicted.outcome);
  }
  for (auto it = available_.begin(); it != available_.end();) {
    const double z = map().find(it->first)->position_map_m.z() - ring_.height_m;
    const DistancePrediction p =
        predict_distances(it->second.q(), z, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps,
                          o.wheel_base_m, step.dt_s, ring_);
    // Eq. 23-24. Not applied when q^i or Q^i would not be finite: the Tx is then discarded below.
    const FilterOutcome predicted =
        it->second.distances.reset(p.q, p.jacobian_q * it->second.covariance() * p.jacobian_q.transpose() +
                                            p.jacobian_wheels * u * p.jacobian_wheels.transpose());
    it->second.measurement_covariance =
        p.jacobian_q * it->second.measurement_covariance * p.jacobian_q.transpose();
    // Eq. 31-32: discard a Tx whose distances have grown too uncertain.
    if (predicted != FilterOutcome::kApplied ||
        it->second.covariance().diagonal().maxCoeff() > params_.discard_variance_m2) {
      it = available_.erase(it);
    } else {
      ++it;
    }
  }
  if (pending_observation_) observe();
  return InputResult::ok();
}

InputResult Duhl::update(const RangeMeasurement& r) {
  if (const InputResult checked = check_range(r, map(), 3); !checked.accepted) return checked;
  if (has_pose() && params_.range_pose_gate > 0.0) {
    // Not in the paper: an echo. The distance the pose predicts (eq. 28) with its variance
    // (eq. 29), not the Tx's own estimate q^i: that one may have drifted (the gate below), the
    // pose is what every Tx agrees on.
    const DistanceInit expected = initial_distances(ekf_.state(), ekf_.covariance(),
                                                    map().find(r.beacon_id)->position_map_m, ring_);
    const double innovation_m = r.range_m - expected.q(r.receiver_id);
    const double variance_m2 = expected.covariance(r.receiver_id, r.receiver_id) + r.variance_m2;
    if (innovation_m * innovation_m > params_.range_pose_gate * variance_m2) {
      if (++consecutive_ranges_gated_ >= params_.lost_after_gated_ranges) lose_track();
      return InputResult::rejected(Rejection::kGatedNis);
    }
    consecutive_ranges_gated_ = 0;
  }
  auto it = available_.find(r.beacon_id);
  if (it != available_.end() && params_.distance_innovation_gate > 0.0) {
    // Not in the paper: an estimate its own measurement contradicts (at 1.02 m/s a turn can
    // carry q^i far from the truth within one firing cycle) is discarded as eq. 31-32 would
    // discard an uncertain one, then initialized anew below. Without this, trajectory 4 lost
    // track on 6 of 10 seeds (E_p RMS 0.24-1.29 m on those).
    const double innovation_m = r.range_m - it->second.q()(r.receiver_id);
    const double variance_m2 = it->second.covariance()(r.receiver_id, r.receiver_id) + r.variance_m2;
    if (innovation_m * innovation_m > params_.distance_innovation_gate * variance_m2) {
      available_.erase(it);
      it = available_.end();
      ++contradicted_txs_;
    }
  }
  if (it == available_.end()) {
    FilterOutcome outcome = FilterOutcome::kApplied;
    std::optional<TxEstimate> fresh = new_tx_estimate(r, outcome);
    if (!fresh) return InputResult::of(outcome);
    it = available_.emplace(r.beacon_id, std::move(*fresh)).first;
  }
  // Eq. 25-27 for the one receiver this range is from (R diagonal: one scalar update per
  // receiver is the same as the three at once), Joseph form, on the Tx's own filter. H = e_l^T
  // is read from a constant table, not written at a run-time index: such a store, read back at
  // once as a packet, cannot be forwarded and stalls the update.
  static const std::array<Mat<1, 3>, 3> kReceiverRow = {Mat<1, 3>(1.0, 0.0, 0.0), Mat<1, 3>(0.0, 1.0, 0.0),
                                                        Mat<1, 3>(0.0, 0.0, 1.0)};
  const UpdateResult result = it->second.distances.update(
      LinearModel<1, 3>(kReceiverRow[r.receiver_id], Mat<1, 1>(r.variance_m2)), Vec<1>(r.range_m));
  if (!result.applied()) return InputResult::of(result.outcome);
  // This receiver's distance now carries the measurement's own variance (eq. 27), and no longer
  // any error shared with the other two.
  DistanceCov& measured = it->second.measurement_covariance;
  measured.row(r.receiver_id).setZero();
  measured.col(r.receiver_id).setZero();
  measured(r.receiver_id, r.receiver_id) = r.variance_m2;
  pending_observation_ = true;  // the UHL runs at the next odometry step, once all receivers are in
  return InputResult::ok();
}

std::optional<Duhl::TxEstimate> Duhl::new_tx_estimate(const RangeMeasurement& r, FilterOutcome& outcome) const {
  TxEstimate fresh;
  if (has_pose()) {  // eq. 28-29, then eq. 30
    const DistanceInit init =
        initial_distances(ekf_.state(), ekf_.covariance(), map().find(r.beacon_id)->position_map_m, ring_);
    outcome = fresh.distances.reset(init.q, init.covariance);
  } else {
    // No pose yet: the measured distance stands for the three, the unmeasured ones loosely.
    outcome = fresh.distances.reset(Distances::Constant(r.range_m),
                                    std::pow(params_.unmeasured_sigma_m, 2) * DistanceCov::Identity());
  }
  if (outcome != FilterOutcome::kApplied) return std::nullopt;
  // Until a receiver is measured, everything about its distance came from the pose.
  fresh.measurement_covariance = fresh.covariance();
  return fresh;
}

// R for the UHL pose. Eq. 21 propagates the full Q^i of eq. 24. Taken as printed, it is not the
// covariance of the innovation z - x (measured: NEES in the 95 % band for 39-48 % of steps):
//  - the odometry noise eq. 24 adds to Q^i since the Tx was last measured is the noise eq. 16
//    adds to P over the same interval (both integrate the same wheel readings): counted in R too,
//    it is counted twice;
//  - each Tx's distances enter every correction until the Tx is measured again, about |T_A|
//    corrections: their information is counted |T_A| times.
// So R here propagates only the measurement part of Q^i (TxEstimate::measurement_covariance)
// and scales it by |T_A|, so that over the corrections that reuse a measurement it carries its
// information once (covariance intersection's equal split).
Duhl::UhlFix Duhl::solve(std::optional<std::uint32_t> left_out) const {
  std::vector<TxDistances> txs;
  std::vector<DistanceCov> covariances;
  std::vector<TxBelief> beliefs;
  // |T_A| of the Txs this solve takes (see observation R above).
  const double reuse = static_cast<double>(available_.size() - (left_out && available_.count(*left_out) ? 1 : 0));
  for (const auto& [id, e] : available_) {
    if (id == left_out) continue;
    const Eigen::Vector3d& tx_map_m = map().find(id)->position_map_m;
    txs.push_back({tx_map_m, e.q()});
    covariances.push_back(params_.observation_covariance_as_printed ? e.covariance()
                                                                    : reuse * e.measurement_covariance);
    beliefs.push_back({tx_map_m, e.q(), e.covariance()});
  }
  UhlFix fix;
  if (txs.size() < kMinTxs) {
    fix.z.failure = "fewer than two Txs";
    return fix;
  }
  fix.z = solve_uhl(txs, params_.uhl);
  if (!fix.z.ok) return fix;
  fix.r = uhl_observation_covariance(txs, fix.z, covariances, params_.uhl) + 1e-9 * Cov3::Identity();
  fix.explains = explains_distances(beliefs, fix.z.pose, fix.r, ring_, params_.start_residual_gate_sigma);
  return fix;
}

// Not in the paper: a UHL pose from an echo. Before the filter is (re)started from a pose, the
// pose must explain every Tx's distances.
std::optional<Duhl::UhlFix> Duhl::start_fix(UhlFix all) {
  if (all.explains) return all;
  if (available_.size() > kMinTxs) {
    for (const auto& entry : available_) {
      const std::uint32_t id = entry.first;
      UhlFix others = solve(id);
      if (others.z.ok && others.explains) {
        available_.erase(id);
        ++refused_start_txs_;
        return others;
      }
    }
  }
  // Which one is wrong cannot be told (two Txs, or no Tx without which the others agree): every
  // Tx is measured again.
  refused_start_txs_ += available_.size();
  available_.clear();
  uhl_failure_ = "the Txs' distances contradicted each other (an echo): measured again";
  return std::nullopt;
}

void Duhl::observe() {
  pending_observation_ = false;
  if (available_.size() < kMinTxs) return;
  const UhlFix fix = solve(std::nullopt);
  if (!fix.z.ok) {
    uhl_failure_ = fix.z.failure;
    return;
  }
  const StampNs now = *now_ns();
  if (!has_pose()) {
    const std::optional<UhlFix> checked = start_fix(fix);
    if (!checked) return;
    ekf_.reset(checked->z.pose, checked->r);
    start(now);
    consecutive_ranges_gated_ = 0;
    return;
  }
  // Eq. 17-20 with J_h,x = I.
  const UpdateResult result = ekf_.update(PoseObservationModel(fix.r), fix.z.pose, params_.observation_nis_gate);
  if (result.applied()) {
    corrected(now);
    consecutive_gated_ = 0;
  } else if (params_.reinitialize_after_gated > 0 &&
             ++consecutive_gated_ >= params_.reinitialize_after_gated) {
    // The UHL and the filter disagree for too long: trust the beacons, once their pose explains
    // them (start_fix; until then the next UHL pose tries again).
    const std::optional<UhlFix> checked = start_fix(fix);
    if (!checked) return;
    ekf_.reset(checked->z.pose, checked->r);
    corrected(now);
    consecutive_gated_ = 0;
    consecutive_ranges_gated_ = 0;
  }
}

std::vector<Estimator::StateValue> Duhl::state_values() const {
  return {{"tx_estimates_contradicted", static_cast<double>(contradicted_txs_), 0.0},
          {"start_txs_refused", static_cast<double>(refused_start_txs_), 0.0}};
}

void Duhl::lose_track() {
  forget_pose();  // found again from the beacons alone, as at the start
  available_.clear();
  consecutive_gated_ = 0;
  consecutive_ranges_gated_ = 0;
}

bool Duhl::place(const Pose2& pose, const Cov3& covariance) {
  ekf_.reset(pose, covariance);  // the distance estimates stay: they come from the measurements
  consecutive_gated_ = 0;
  consecutive_ranges_gated_ = 0;
  return true;
}

StartupWait Duhl::waiting_for() const {
  if (!now_ns()) return StartupWait{StartupCondition::kNoOdometry, 0.0, 0.0, {}};
  if (available_.size() < kMinTxs) {
    return StartupWait{StartupCondition::kTooFewBeacons,
                       static_cast<double>(available_.size()),
                       static_cast<double>(kMinTxs),
                       refused_start_txs_ > 0 ? uhl_failure_ : std::string()};
  }
  return StartupWait{StartupCondition::kFixFailed, 0.0, 0.0, "uhl: " + uhl_failure_};
}

UhlOptions UhlLast2::options_from(const EstimatorConfig& config) {
  ParameterReader in(config, "uhl_last2");
  const UhlOptions o = uhl_options(config, in);
  in.finish();
  return o;
}

UhlLast2::UhlLast2(const EstimatorConfig& config)
    : EstimatorBase(0.2), ring_(ring_of(config)), uhl_(options_from(config)) {
  if (!three_on_a_circle(config)) {
    throw std::invalid_argument(
        "uhl_last2 needs three receivers on a circle at 0, 120, 240 degrees (seed 000 eq. 1)");
  }
}

InputResult UhlLast2::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = advance(o);
  if (!step.result.accepted) return step.result;
  if (!pending_) return InputResult::ok();
  pending_ = false;
  // The last two Txs heard by all three receivers, each firing's distances possible for the
  // ring (update).
  std::vector<TxDistances> txs;
  std::vector<DistanceCov> covariances;
  for (auto it = firings_.rbegin(); it != firings_.rend() && txs.size() < kMinTxs; ++it) {
    if (!(it->heard[0] && it->heard[1] && it->heard[2])) continue;
    if (it->impossible) continue;
    txs.push_back({map().find(it->beacon_id)->position_map_m, it->d});
    covariances.push_back(it->variance_m2 * DistanceCov::Identity());
  }
  heard_by_all_ = txs.size();
  if (txs.size() < kMinTxs) return InputResult::ok();
  const UhlSolution z = solve_uhl(txs, uhl_);
  if (!z.ok) {
    uhl_failure_ = z.failure;
    return InputResult::ok();
  }
  last_ = {z.pose, uhl_observation_covariance(txs, z, covariances, uhl_) + 1e-9 * Cov3::Identity()};
  start(o.stamp_ns);
  return InputResult::ok();
}

InputResult UhlLast2::update(const RangeMeasurement& r) {
  if (const InputResult checked = check_range(r, map(), 3); !checked.accepted) return checked;
  // A new firing when this Tx is not the newest, or this receiver was already heard from it.
  if (firings_.empty() || firings_.back().beacon_id != r.beacon_id || firings_.back().heard[r.receiver_id]) {
    firings_.erase(std::remove_if(firings_.begin(), firings_.end(),
                                  [&](const Firing& f) { return f.beacon_id == r.beacon_id; }),
                   firings_.end());
    firings_.push_back({r.beacon_id, Distances::Zero()});
    if (firings_.size() > 8) firings_.erase(firings_.begin());
  }
  Firing& f = firings_.back();
  f.d(r.receiver_id) = r.range_m;
  f.heard[r.receiver_id] = true;
  f.variance_m2 = r.variance_m2;
  pending_ = true;
  // Not in the paper: the firing's three distances impossible for the ring (possible_distances:
  // an echo's extra path breaks the triangle inequality) leave it out; the range that shows it
  // is refused, so that it is counted.
  if (f.heard[0] && f.heard[1] && f.heard[2] && !possible_distances(f.d, f.variance_m2, ring_)) {
    f.impossible = true;
    return InputResult::rejected(Rejection::kEchoOfFiring);
  }
  return InputResult::ok();
}

StartupWait UhlLast2::waiting_for() const {
  if (!now_ns()) return StartupWait{StartupCondition::kNoOdometry, 0.0, 0.0, {}};
  if (heard_by_all_ < kMinTxs) {
    return StartupWait{StartupCondition::kTooFewBeacons, static_cast<double>(heard_by_all_),
                       static_cast<double>(kMinTxs), "heard by all three receivers"};
  }
  return StartupWait{StartupCondition::kFixFailed, 0.0, 0.0, "uhl: " + uhl_failure_};
}

namespace {
BEACONLOC_REGISTER_ESTIMATOR(
    "duhl", "seed 000 DUHL: EKF corrected by the UHL pose of the dynamically estimated distances",
    "seed000_trajectory1.yaml", [](const EstimatorConfig& config) { return std::make_unique<Duhl>(config); });
BEACONLOC_REGISTER_ESTIMATOR("uhl_last2", "seed 000's baseline: UHL on the last two Txs' measured distances",
                             "seed000_trajectory1.yaml", [](const EstimatorConfig& config) {
                               return std::make_unique<UhlLast2>(config);
                             });
}  // namespace

}  // namespace beaconloc::duhl
