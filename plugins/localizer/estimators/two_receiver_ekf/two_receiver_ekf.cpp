#include "two_receiver_ekf.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/models/linear_motion.hpp"
#include "beaconloc/core/models/point_range_model.hpp"

namespace beaconloc {

TwoReceiverEkfParameters TwoReceiverEkfParameters::from(const EstimatorConfig& c) {
  namespace ranges = parameter_ranges;
  ParameterReader in(c, "two_receiver_ekf");
  TwoReceiverEkfParameters p;
  p.process_noise_m2ps = in.real("process_noise_m2ps", p.process_noise_m2ps, ParameterRange::closed(0.0, 1.0));
  p.initial_sigma_m = in.real("initial_sigma_m", p.initial_sigma_m, ranges::kPositionSigmaM);
  p.initial_sigma_rad = in.real("initial_sigma_rad", p.initial_sigma_rad, ranges::kHeadingSigmaRad);
  p.nis_gate = in.real("nis_gate", p.nis_gate, ranges::kChiSquareGate);
  p.gate_after_agreeing = in.count("gate_after_agreeing", p.gate_after_agreeing, 1, 1000);
  p.open_gate_echo_sigma =
      in.real("open_gate_echo_sigma", p.open_gate_echo_sigma, ParameterRange::closed(0.0, 100.0));
  p.separation_gate_sigma =
      in.real("separation_gate_sigma", p.separation_gate_sigma, ParameterRange::above(0.0, 100.0));
  p.max_odometry_gap_s = in.real("max_odometry_gap_s", p.max_odometry_gap_s, ranges::kDataDurationS);
  in.finish();
  return p;
}

TwoReceiverEkf::TwoReceiverEkf(const EstimatorConfig& config)
    : EstimatorBase(TwoReceiverEkfParameters::from(config).max_odometry_gap_s),
      receiver_z_m_(config.receivers.receiver_height_m),
      params_(TwoReceiverEkfParameters::from(config)) {
  if (config.receivers.size() != 2) {
    throw std::invalid_argument(name() + " takes the ranges of two receivers, front and rear (seed 004 Sec. 2)");
  }
  pair_ = {config.receivers.receivers_base_m[kFront], config.receivers.receivers_base_m[kRear]};
  if (!(pair_.separation_m() > 1e-3)) {
    throw std::invalid_argument(name() + ": the two receivers must be apart (eq. 11 takes the heading from them)");
  }
  if (config.initial_pose) {
    if (!config.initial_pose->allFinite()) throw std::invalid_argument(name() + ": the initial pose must be finite");
    const double sxy2 = params_.initial_sigma_m * params_.initial_sigma_m;
    place(*config.initial_pose,
          Cov3(Eigen::Vector3d(sxy2, sxy2, params_.initial_sigma_rad * params_.initial_sigma_rad).asDiagonal()));
    start(0);
  }
}

// Each receiver where the pose puts it: P_i = t + R(yaw) b_i, its covariance the pose's carried
// by [I, dR/dyaw b_i]. Both or neither: a receiver refused leaves the pair as it was.
// Eq. 12's independence: each receiver is given the pose's whole position uncertainty, which the
// pair then reads back as a heading far less sure than the pose's (their shared error is not
// held); a start is never surer than it was given.
bool TwoReceiverEkf::place(const Pose2& pose, const Cov3& covariance) {
  const std::array<Eigen::Vector2d, 2> base = {pair_.front_base_m, pair_.rear_base_m};
  std::array<Ekf<2>, 2> placed = receivers_;
  for (std::size_t i = 0; i < 2; ++i) {
    Eigen::Matrix<double, 2, 3> j;
    j.leftCols<2>().setIdentity();
    j.col(2) << -std::sin(pose.z()) * base[i].x() - std::cos(pose.z()) * base[i].y(),
        std::cos(pose.z()) * base[i].x() - std::sin(pose.z()) * base[i].y();
    if (placed[i].reset(transform_point(pose, base[i]), j * covariance * j.transpose()) != FilterOutcome::kApplied) {
      return false;
    }
  }
  receivers_ = placed;
  gates_ = {};  // a new start is a guess again
  return true;
}

PairPose TwoReceiverEkf::pair_pose() const {
  return pose_from_receivers(receivers_[kFront].state(), receivers_[kFront].covariance(),
                             receivers_[kRear].state(), receivers_[kRear].covariance(), pair_);
}

EstimatorBase::PoseBelief TwoReceiverEkf::pose_belief() const {
  const PairPose p = pair_pose();
  return {p.pose_map_base, p.covariance};
}

// Eq. 3: each receiver moved by the odometry, r_k+1 = r_k + step(u_k) + q_k. The step is the
// receiver's displacement under the wheel velocities at the pair's heading; its covariance holds
// the wheels' noise and the heading's uncertainty (receiver_step), and q_k the floor.
InputResult TwoReceiverEkf::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = advance(o);
  if (!step.integrate || !has_pose()) return step.result;
  const PairPose pose = pair_pose();
  const Eigen::Matrix2d wheel_covariance =
      o.wheel_velocity_covariance + params_.wheel_velocity_variance_floor_m2ps2 * Eigen::Matrix2d::Identity();
  const std::array<Eigen::Vector2d, 2> base = {pair_.front_base_m, pair_.rear_base_m};
  std::array<Ekf<2>, 2> moved = receivers_;  // both receivers move, or neither
  for (std::size_t i = 0; i < 2; ++i) {
    const ReceiverStep s = receiver_step(pose.pose_map_base, pose.covariance(2, 2), base[i], o.wheel_velocity_right_mps,
                                         o.wheel_velocity_left_mps, wheel_covariance, o.wheel_base_m, step.dt_s);
    const LinearMotion<2, 2> motion(Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Identity(), s.covariance,
                                    params_.process_noise_m2ps * step.dt_s * Eigen::Matrix2d::Identity());
    const PredictResult predicted = moved[i].predict(motion, s.displacement_m, step.dt_s);
    if (!predicted.applied()) return InputResult::of(predicted.outcome);
  }
  receivers_ = moved;
  return InputResult::ok();
}

// Eq. 4-10: the range updates the EKF of the receiver that heard it (receiver 0 front, 1 rear),
// at the filter's current time (pushed in stamp order, within one odometry period of it).
InputResult TwoReceiverEkf::update(const RangeMeasurement& r) {
  if (const InputResult checked = check_range(r, map(), 2); !checked.accepted) return checked;
  if (!has_pose()) return InputResult::rejected(Rejection::kNoInitialPose);
  // The other receiver heard the same firing first when its path is shorter: an echo here is
  // the longer one of the pair. (Heard first, an echo cannot be told: the direct range after it
  // is shorter.)
  const std::optional<RangeMeasurement>& other = last_heard_[1 - r.receiver_id];
  last_heard_[r.receiver_id] = r;
  if (other && other->beacon_id == r.beacon_id && std::abs(r.stamp_ns - other->stamp_ns) <= kSameFiringNs &&
      r.range_m > other->range_m &&
      !ranges_of_one_firing_agree(r.range_m, other->range_m, pair_.separation_m(), r.variance_m2 + other->variance_m2)) {
    return InputResult::rejected(Rejection::kEchoOfFiring);
  }
  Ekf<2>& filter = receivers_[r.receiver_id];
  GateState& gate = gates_[r.receiver_id];
  double variance_m2 = r.variance_m2;
  std::optional<double> declared_nis;  // of a range fused down-weighted: its NIS as declared
  if (!gate.closed && params_.open_gate_echo_sigma > 0.0) {  // TwoReceiverEkfParameters::open_gate_echo_sigma
    const PointRangeModel as_declared(receiver_z_m_, map().find(r.beacon_id)->position_map_m, r.variance_m2);
    const auto prior = filter.prior_innovation(as_declared, PointRangeModel::Vector(r.range_m));
    const double innovation_m = prior ? prior->innovation(0) : 0.0;  // unusable: update() refuses it
    const double s_m2 = prior ? prior->state_covariance(0, 0) + r.variance_m2 : r.variance_m2;
    const double limit_m = params_.open_gate_echo_sigma * std::sqrt(s_m2);
    if (innovation_m > limit_m) {
      variance_m2 += (innovation_m * innovation_m / (limit_m * limit_m) - 1.0) * s_m2;
      declared_nis = innovation_m * innovation_m / s_m2;
    }
  }
  const PointRangeModel model(receiver_z_m_, map().find(r.beacon_id)->position_map_m, variance_m2);
  const UpdateResult result = filter.update(
      model, PointRangeModel::Vector(r.range_m), gate.closed ? params_.nis_gate : std::numeric_limits<double>::infinity());
  if (result.outcome == FilterOutcome::kGated) {
    gate.agreeing = 0;
    if (++gate.gated >= params_.gate_after_agreeing) gate = GateState{};  // lost: open the gate again
    return InputResult::rejected(Rejection::kGatedNis);
  }
  if (!result.applied()) return InputResult::of(result.outcome);
  gate.gated = 0;
  // Agreeing as declared: a down-weighted range's NIS is open_gate_echo_sigma^2 by construction.
  gate.agreeing = declared_nis.value_or(result.nis) <= params_.nis_gate ? gate.agreeing + 1 : 0;
  if (gate.agreeing >= params_.gate_after_agreeing) gate.closed = true;
  corrected(std::max(r.stamp_ns, now_ns().value_or(r.stamp_ns)));
  return InputResult::ok();
}

// The two receivers are one rigid body: estimates whose distance contradicts the mounting's
// separation (one of them pulled onto a wrong solution) cannot both be right.
bool TwoReceiverEkf::suspect() const {
  const Eigen::Vector2d d = receivers_[kFront].state() - receivers_[kRear].state();
  const double distance_m = d.norm();
  if (distance_m < 1e-9) return true;
  const Eigen::Vector2d u = d / distance_m;
  const double variance = u.dot((receivers_[kFront].covariance() + receivers_[kRear].covariance()) * u);
  return std::abs(distance_m - pair_.separation_m()) > params_.separation_gate_sigma * std::sqrt(variance);
}

namespace {
BEACONLOC_REGISTER_ESTIMATOR("two_receiver_ekf",
                             "seed 004: one EKF per receiver (front, rear), the pose from the pair",
                             "seed004_two_receivers.yaml",
                             [](const EstimatorConfig& config) {
                               return std::make_unique<TwoReceiverEkf>(config);
                             });
}  // namespace

}  // namespace beaconloc
