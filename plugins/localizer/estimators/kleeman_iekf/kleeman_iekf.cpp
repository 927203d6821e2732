#include "kleeman_iekf/kleeman_iekf.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/models/linear_model.hpp"
#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc {

namespace {

using kleeman::Covariance;
using kleeman::State;
namespace idx = kleeman;

// The chi-square (1 dof) gate a direct pulse exceeds with probability p: z^2 for the two-sided
// normal tail erfc(z / sqrt 2) = p, by bisection (the tail falls monotonically in z).
double one_dof_gate(double probability) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > probability ? lo : hi) = mid;
  }
  return hi * hi;
}

// The slowest sound the filter may meet (-40 C, the scenario limit): the longest flight is the
// beacons' extent at this speed.
const double kSlowestSoundMps = speed_of_sound_mps(-40.0);
// Echoes arrive up to this much after the direct path's flight and still belong to its slot.
constexpr double kEchoAllowanceS = 0.01;

}  // namespace

KleemanParameters KleemanParameters::from(const EstimatorConfig& c) {
  namespace ranges = parameter_ranges;
  ParameterReader in(c, "kleeman_iekf");
  KleemanParameters p;
  p.slot_period_s = in.real("slot_period_s", p.slot_period_s, ParameterRange::closed(0.01, 2.0));
  p.slot_period_sigma_s = in.real("slot_period_sigma_s", p.slot_period_sigma_s, ParameterRange::above(0.0, 0.1));
  p.marked_beacon_id = in.count("marked_beacon_id", p.marked_beacon_id, 0, 1 << 30);
  p.arrival_sigma_s = in.real("arrival_sigma_s", p.arrival_sigma_s, ParameterRange::above(0.0, 0.1));
  p.startup_arrival_sigma_s =
      in.real("startup_arrival_sigma_s", p.startup_arrival_sigma_s, ParameterRange::above(0.0, 0.1));
  p.startup_slots = in.count("startup_slots", p.startup_slots, 0, 10000);
  p.initial_speed_of_sound_mps =
      in.real("initial_speed_of_sound_mps", p.initial_speed_of_sound_mps, ParameterRange::closed(300.0, 400.0));
  p.initial_speed_of_sound_sigma_mps =
      in.real("initial_speed_of_sound_sigma_mps", p.initial_speed_of_sound_sigma_mps, ParameterRange::above(0.0, 50.0));
  p.echo_gate_probability =
      in.real("echo_gate_probability", p.echo_gate_probability, ParameterRange::open(0.0, 1.0));
  p.startup_cycles = in.count("startup_cycles", p.startup_cycles, 1, 20);
  p.unknown_speed_mps = in.real("unknown_speed_mps", p.unknown_speed_mps, ParameterRange::above(0.0, 10.0));
  p.heading_fit_cycles = in.count("heading_fit_cycles", p.heading_fit_cycles, 1, 20);
  p.heading_fit_min_travel_m =
      in.real("heading_fit_min_travel_m", p.heading_fit_min_travel_m, ParameterRange::above(0.0, 100.0));
  p.startup_outlier_gate_s =
      in.real("startup_outlier_gate_s", p.startup_outlier_gate_s, ParameterRange::above(0.0, 0.1));
  p.dead_reckoning = in.flag("dead_reckoning", p.dead_reckoning);
  p.heading_offset_sigma_rad =
      in.real("heading_offset_sigma_rad", p.heading_offset_sigma_rad, ParameterRange::closed(0.0, 1.0));
  p.heading_fraction = in.real("heading_fraction", p.heading_fraction, ParameterRange::closed(0.0, 1.0));
  p.speed_sigma_mps = in.real("speed_sigma_mps", p.speed_sigma_mps, ParameterRange::above(0.0, 10.0));
  p.turn_rate_sigma_radps = in.real("turn_rate_sigma_radps", p.turn_rate_sigma_radps, ParameterRange::above(0.0, 10.0));
  p.noise.position_m = in.real("position_noise_m", p.noise.position_m, ParameterRange::closed(0.0, 1.0));
  p.noise.speed_mps = in.real("speed_noise_mps", p.noise.speed_mps, ParameterRange::closed(0.0, 10.0));
  p.noise.cycle_s = in.real("cycle_noise_s", p.noise.cycle_s, ParameterRange::closed(0.0, 1e-3));
  p.noise.fire_time_s = in.real("fire_time_noise_s", p.noise.fire_time_s, ParameterRange::closed(0.0, 1e-2));
  p.noise.speed_of_sound_mps =
      in.real("speed_of_sound_noise_mps", p.noise.speed_of_sound_mps, ParameterRange::closed(0.0, 10.0));
  p.max_iterations = in.count("max_iterations", p.max_iterations, 1, 100);
  p.max_odometry_gap_s = in.real("max_odometry_gap_s", p.max_odometry_gap_s, ranges::kDataDurationS);
  p.max_ok_heading_sigma_rad =
      in.real("max_ok_heading_sigma_rad", p.max_ok_heading_sigma_rad, ranges::kHeadingSigmaRad);
  p.lost_after_gated = in.count("lost_after_gated", p.lost_after_gated, 1, 10000);
  in.finish();
  return p;
}

KleemanIekf::KleemanIekf(const EstimatorConfig& config) : KleemanIekf(config, KleemanParameters::from(config)) {}

KleemanIekf::KleemanIekf(const EstimatorConfig& config, const KleemanParameters& params)
    : EstimatorBase(params.max_odometry_gap_s),
      params_(params),
      receivers_(config.receivers),
      nis_gate_(one_dof_gate(params.echo_gate_probability)) {
  // Eq. 17-21 put the receiver at the robot's position (Sec. 4: "mounted above the centre of the
  // driving wheel base"); a receiver elsewhere would bias every arrival by its lever arm.
  for (const Eigen::Vector2d& r : receivers_.receivers_base_m) {
    if (r.norm() > 0.01) {
      throw std::invalid_argument(
          "kleeman_iekf: seed 002's arrival model (eq. 17-21) has the receiver at the robot's origin; a "
          "receiver is " + std::to_string(r.norm()) + " m from it");
    }
  }
  if (receivers_.receivers_base_m.empty()) throw std::invalid_argument("kleeman_iekf: the robot has no receiver");
}

void KleemanIekf::set_beacon_map(const BeaconMap& map) {
  EstimatorBase::set_beacon_map(map);
  // Sec. 2: the beacons fire in the order of their numbers (123456123...).
  order_.clear();
  Eigen::AlignedBox3d extent;
  for (const Beacon& b : map.beacons()) {
    order_.push_back(b.id);
    extent.extend(b.position_map_m);
  }
  std::sort(order_.begin(), order_.end());
  const auto marked = static_cast<std::uint32_t>(params_.marked_beacon_id);
  firing_.reset();
  if (std::find(order_.begin(), order_.end(), marked) != order_.end()) firing_.emplace(order_, marked);
  // The longest flight: across the beacons' extent, down to the receiver, at the slowest sound.
  const Eigen::Vector3d span(extent.sizes().x(), extent.sizes().y(),
                             std::max(std::abs(extent.max().z() - receivers_.receiver_height_m),
                                      std::abs(extent.min().z() - receivers_.receiver_height_m)));
  max_flight_s_ = std::min(map.beacons().empty() ? 0.0 : span.norm() / kSlowestSoundMps + kEchoAllowanceS,
                           0.9 * params_.slot_period_s);
}

const Beacon* KleemanIekf::beacon(std::uint32_t id) const { return map().find(id); }

InputResult KleemanIekf::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = advance(o);
  if (!step.result.accepted) return step.result;
  if (!epoch_ns_) epoch_ns_ = o.stamp_ns;
  if (step.integrate) track_.add(o, seconds(o.stamp_ns), step.dt_s);
  // Kept: the odometry since the oldest pulse of the window, and since the filter's slot.
  double keep_from = seconds(o.stamp_ns) - 1.0;
  if (!window_.empty()) keep_from = std::min(keep_from, window_.front().arrival_s - 1.0);
  if (filter_) keep_from = std::min(keep_from, filter_->state()(idx::kFireTime) - 1.0);
  track_.forget_before(keep_from);
  return step.result;
}

InputResult KleemanIekf::update(const RangeMeasurement& range) {
  // A bad range gets the reason any estimator gives it; a good one is of no use here: it hears
  // pulse arrivals (beacon_input), and the localizer never gives it a range.
  if (const InputResult checked = check_range_numbers(range); !checked.accepted) return checked;
  return InputResult::rejected(Rejection::kBeaconsUnused);
}

InputResult KleemanIekf::update_pulse(const PulseArrivalSample& p) {
  if (p.stamp_ns < 0) return InputResult::rejected(Rejection::kInvalidStamp);
  if (p.receiver_id >= receivers_.size()) return InputResult::rejected(Rejection::kUnknownReceiver);
  if (map().empty()) return InputResult::rejected(Rejection::kNoBeaconMap);
  if (!firing_) return InputResult::rejected(Rejection::kUnknownBeacon);  // the marked beacon is not in the map
  // The odometry stamps the pose and carries it between slots (and epoch_ns_ is set with it).
  if (!now_ns() || !epoch_ns_) return InputResult::rejected(Rejection::kRangesWithoutOdometry);
  if (p.stamp_ns < *now_ns() - kMeasurementHorizonNs) return InputResult::rejected(Rejection::kStaleRange);
  const double arrival_s = seconds(p.stamp_ns);
  return filter_ ? track(p, arrival_s) : collect_startup(p, arrival_s);
}

kleeman::StartupFitSettings KleemanIekf::fit_settings() const {
  kleeman::StartupFitSettings s;
  s.receiver_z_m = receivers_.receiver_height_m;
  s.arrival_sigma_s = params_.arrival_sigma_s;
  s.outlier_gate_s = params_.startup_outlier_gate_s;
  s.speed_of_sound_mps = params_.initial_speed_of_sound_mps;
  s.speed_of_sound_sigma_mps = params_.initial_speed_of_sound_sigma_mps;
  s.cycle_s = params_.slot_period_s;
  s.cycle_sigma_s = params_.slot_period_sigma_s;
  s.min_beacons = std::min<int>(4, static_cast<int>(order_.size()));
  return s;
}

// Start-up (issue 15 item 5): the pulses after the first double burst, numbered by their slot
// from it with the nominal T (a flight shorter than half a slot leaves each in its own), until
// startup_cycles cycles are in; then the fit.
InputResult KleemanIekf::collect_startup(const PulseArrivalSample& p, double arrival_s) {
  const bool double_burst = p.mark == PulseMark::kDouble;
  if (!sync_arrival_s_) {
    if (!double_burst) return InputResult::rejected(Rejection::kPulseBeforeDoubleBurst);
    sync_arrival_s_ = arrival_s;
    window_.clear();
  }
  const double slots = (arrival_s - *sync_arrival_s_) / params_.slot_period_s;
  const auto n = static_cast<std::int64_t>(order_.size());
  if (!(slots >= -0.5) || slots > static_cast<double>((params_.startup_cycles + 1) * n)) {
    // Before the sync (out of order) or far past the window (a long silence): start again.
    sync_arrival_s_.reset();
    window_.clear();
    return double_burst ? collect_startup(p, arrival_s) : InputResult::rejected(Rejection::kPulseBeforeDoubleBurst);
  }
  const std::int64_t slot = std::llround(slots);
  if (std::abs(slots - static_cast<double>(slot)) * params_.slot_period_s > max_flight_s_) {
    return InputResult::rejected(Rejection::kPulseBetweenSlots);
  }
  if (!window_.empty() && slot < window_.back().slot) return InputResult::rejected(Rejection::kPulseLate);
  const std::uint32_t marked = static_cast<std::uint32_t>(params_.marked_beacon_id);
  const std::size_t marked_index = static_cast<std::size_t>(std::find(order_.begin(), order_.end(), marked) - order_.begin());
  const std::uint32_t id = order_[(marked_index + static_cast<std::size_t>(slot % n)) % order_.size()];
  if (double_burst && id != marked) {
    // A double burst where the numbering has another beacon: the numbering was wrong; restart from it.
    sync_arrival_s_.reset();
    window_.clear();
    return collect_startup(p, arrival_s);
  }
  window_.push_back({slot, arrival_s, id, beacon(id)->position_map_m});
  if (slot < params_.startup_cycles * n) return InputResult::ok();

  const kleeman::StartupFit fit =
      fit_startup({window_.begin(), window_.end()}, params_.dead_reckoning ? &track_ : nullptr, fit_settings());
  if (!fit.ok) {
    ++startup_fits_failed_;
    last_fit_failure_ = StartupWait{StartupCondition::kFixFailed, 0.0, 0.0, fit.why_not};
    sync_arrival_s_.reset();  // again from the next double burst
    window_.clear();
    return InputResult::ok();  // the pulse was heard; the fit's failure is the start-up's state
  }
  start_from_fit(fit, p.stamp_ns);
  return InputResult::ok();
}

KleemanIekf::FittedPose KleemanIekf::pose_from_fit(const kleeman::StartupFit& fit, double at_s) const {
  using P = kleeman::StartupFit::Parameter;
  const auto at = [](P q) { return static_cast<Eigen::Index>(q); };
  kleeman::DeadReckoning d;
  if (params_.dead_reckoning) {
    d = at_s >= fit.reference_s ? track_.between(fit.reference_s, at_s) : kleeman::DeadReckoning{};
  }
  const double heading = fit.solution(at(P::kHeading));
  const double c = std::cos(heading), s = std::sin(heading);
  FittedPose out;
  out.pose = Pose2(fit.solution(at(P::kX)) + c * d.forward_m - s * d.left_m,
                   fit.solution(at(P::kY)) + s * d.forward_m + c * d.left_m, wrap_angle_rad(heading + d.dtheta_rad));
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();  // d(pose at at_s)/d(x, y, theta at the reference)
  j(0, 2) = -s * d.forward_m - c * d.left_m;
  j(1, 2) = c * d.forward_m - s * d.left_m;
  Eigen::Matrix3d c3;
  const Eigen::Index pose_at[3] = {at(P::kX), at(P::kY), at(P::kHeading)};
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) c3(r, q) = fit.covariance(pose_at[r], pose_at[q]);
  out.covariance = j * c3 * j.transpose();
  out.covariance += Eigen::Vector3d(d.distance_variance, d.distance_variance, d.dtheta_variance).asDiagonal();
  // An unobserved heading (the robot stood still) is uniform: at most a half turn's variance.
  if (!fit.heading_observed || out.covariance(2, 2) > M_PI * M_PI) {
    out.covariance.row(2).setZero();
    out.covariance.col(2).setZero();
    out.covariance(2, 2) = M_PI * M_PI;
  }
  return out;
}

void KleemanIekf::start_from_fit(const kleeman::StartupFit& fit, StampNs stamp_ns) {
  using P = kleeman::StartupFit::Parameter;
  const auto at = [](P q) { return static_cast<Eigen::Index>(q); };
  const std::int64_t slot = window_.back().slot;
  const double slots = static_cast<double>(slot - fit.first_slot);
  const double period = fit.solution(at(P::kCycle));
  const double fire_s = fit.solution(at(P::kFirstFireTime)) + slots * period;
  const FittedPose pose = pose_from_fit(fit, fire_s);
  State x;
  x(idx::kX) = pose.pose.x();
  x(idx::kY) = pose.pose.y();
  x(idx::kHeading) = pose.pose.z();
  x(idx::kCycle) = period;
  x(idx::kFireTime) = fire_s;
  x(idx::kSpeedOfSound) = fit.solution(at(P::kSpeedOfSound));
  double speed_variance = 1.0;  // without dead reckoning: a speed within a few m/s
  x(idx::kSpeed) = 0.0;
  if (params_.dead_reckoning) {
    const kleeman::DeadReckoning d = track_.between(fire_s - period, fire_s);
    x(idx::kSpeed) = d.distance_m / period;
    speed_variance = d.distance_variance / (period * period) + params_.speed_sigma_mps * params_.speed_sigma_mps;
  }
  heading_known_ = pose.covariance(2, 2) <= params_.max_ok_heading_sigma_rad * params_.max_ok_heading_sigma_rad;
  if (!heading_known_) {  // carried at v = 0 until the heading is found (heading_known_)
    x(idx::kSpeed) = 0.0;
    speed_variance = 1e-12;
  }
  Covariance p = Covariance::Zero();
  const Eigen::Index pose_at[3] = {idx::kX, idx::kY, idx::kHeading};
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) p(pose_at[r], pose_at[q]) = pose.covariance(r, q);
  // t0 of the current slot = t_first + slots T; T and s as fitted, with their correlations.
  Eigen::Matrix3d g = Eigen::Matrix3d::Zero();  // (T, t0, s) from (t_first, T, s)
  g(0, 1) = 1.0;
  g(1, 0) = 1.0;
  g(1, 1) = slots;
  g(2, 2) = 1.0;
  Eigen::Matrix3d c3;
  const Eigen::Index fit_at[3] = {at(P::kFirstFireTime), at(P::kCycle), at(P::kSpeedOfSound)};
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) c3(r, q) = fit.covariance(fit_at[r], fit_at[q]);
  const Eigen::Matrix3d timing = g * c3 * g.transpose();
  const Eigen::Index timing_at[3] = {idx::kCycle, idx::kFireTime, idx::kSpeedOfSound};
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) p(timing_at[r], timing_at[q]) = timing(r, q);
  p(idx::kSpeed, idx::kSpeed) = speed_variance;
  filter_.emplace(kleeman::state_space(), IteratedEkfOptions{params_.max_iterations, 1e-9});
  if (filter_->reset(x, p) != FilterOutcome::kApplied) {
    filter_.reset();
    ++startup_fits_failed_;
    last_fit_failure_ = StartupWait{StartupCondition::kFixFailed, 0.0, 0.0, "the fit's covariance is not positive definite"};
    sync_arrival_s_.reset();
    window_.clear();
    return;
  }
  // The firing order, numbered as the window was; the filter's slot is the window's last.
  firing_.emplace(order_, static_cast<std::uint32_t>(params_.marked_beacon_id));
  bool first = true;  // the window starts at the first double burst
  for (const kleeman::SlotPulse& w : window_) {
    firing_->heard(w.slot, first);
    first = false;
  }
  slot_index_ = slot;
  slots_since_start_ = 0;
  travel_.clear();
  consecutive_gated_ = 0;
  consecutive_far_ = 0;
  sync_arrival_s_.reset();
  last_fit_failure_.reset();
  start(std::max(stamp_ns, now_ns().value_or(stamp_ns)));
}

void KleemanIekf::lose() {
  filter_.reset();
  travel_.clear();
  forget_pose();
  window_.clear();
  sync_arrival_s_.reset();
  ++losses_;
}

FilterOutcome KleemanIekf::advance_slots(std::int64_t slots) {
  for (std::int64_t i = 0; i < slots; ++i) {
    const State& x = filter_->state();
    const double period = x(idx::kCycle), from = x(idx::kFireTime);
    double dtheta = 0.0, dtheta_variance = 0.0, unknown_travel_variance = 0.0;
    kleeman::SlotNoise noise = params_.noise;
    if (params_.dead_reckoning && !heading_known_) {
      // The heading unknown: no move along it (v = 0), the travel as noise; the turn as eq. 24.
      const kleeman::DeadReckoning d = track_.between(from, from + period);
      unknown_travel_variance = d.distance_m * d.distance_m + d.distance_variance;
      noise.speed_mps = 0.0;  // v stays 0: no pulse may find a speed along an unknown heading
      dtheta = d.dtheta_rad;
      const double model_sigma = params_.heading_offset_sigma_rad + params_.heading_fraction * std::abs(dtheta);
      dtheta_variance = d.dtheta_variance + model_sigma * model_sigma;
    } else if (params_.dead_reckoning) {
      // Eq. 25: the slot's mean dead-reckoned speed measures v, the speed over the slot.
      const kleeman::DeadReckoning d = track_.between(from, from + period);
      const double variance =
          d.distance_variance / (period * period) + params_.speed_sigma_mps * params_.speed_sigma_mps;
      Mat<1, kleeman::kStateSize> h = Mat<1, kleeman::kStateSize>::Zero();
      h(0, idx::kSpeed) = 1.0;
      const UpdateResult speed =
          filter_->update(LinearModel<1, kleeman::kStateSize>(h, Mat<1, 1>(variance)), Vec<1>(d.distance_m / period));
      if (!speed.applied()) return speed.outcome;
      // Eq. 24 and Sec. 3.10: the input dtheta, its variance the odometry's plus an offset and a
      // fraction of the increment.
      dtheta = d.dtheta_rad;
      const double model_sigma = params_.heading_offset_sigma_rad + params_.heading_fraction * std::abs(dtheta);
      dtheta_variance = d.dtheta_variance + model_sigma * model_sigma;
    } else if (!heading_known_) {
      // No dead reckoning and no heading yet: a random walk of the robot's top speed, v = 0.
      const double step = params_.unknown_speed_mps * period;
      unknown_travel_variance = step * step;
      noise.speed_mps = 0.0;
    } else {
      const double turn = params_.turn_rate_sigma_radps * period;
      dtheta_variance = turn * turn;
    }
    const PredictResult predicted =
        filter_->predict(kleeman::SlotTransition(dtheta_variance, noise, unknown_travel_variance), Vec<1>(dtheta), period);
    if (!predicted.applied()) return predicted.outcome;
    ++slot_index_;
    ++slots_since_start_;
    if (!params_.dead_reckoning && !heading_known_) heading_from_travel();
  }
  return FilterOutcome::kApplied;
}

// Without dead reckoning the heading is the direction the beacons see the robot travel: once the
// filter's position moved heading_fit_min_travel_m over at most heading_fit_cycles cycles, the
// heading is that of the displacement and the speed its length over the time, each with the
// variance the two positions' give (lateral sigma over the distance).
void KleemanIekf::heading_from_travel() {
  const State& x = filter_->state();
  const Covariance& p = filter_->covariance();
  travel_.push_back({x(idx::kFireTime), x.head<2>(), 0.5 * (p(idx::kX, idx::kX) + p(idx::kY, idx::kY))});
  const auto span = static_cast<std::size_t>(params_.heading_fit_cycles * order_.size());
  while (travel_.size() > span + 1) travel_.pop_front();
  const TravelPoint& from = travel_.front();
  const TravelPoint& to = travel_.back();
  const Eigen::Vector2d d = to.position_m - from.position_m;
  const double distance = d.norm(), dt = to.t_s - from.t_s;
  if (distance < params_.heading_fit_min_travel_m || !(dt > 0.0)) return;
  const double variance = from.variance_m2 + to.variance_m2;
  const double heading_variance = variance / (distance * distance);
  if (heading_variance > 0.25 * params_.max_ok_heading_sigma_rad * params_.max_ok_heading_sigma_rad) return;
  State next = x;
  next(idx::kHeading) = std::atan2(d.y(), d.x());
  next(idx::kSpeed) = distance / dt;
  Covariance next_p = p;
  for (const Eigen::Index i : {idx::kHeading, idx::kSpeed}) {
    next_p.row(i).setZero();
    next_p.col(i).setZero();
  }
  next_p(idx::kHeading, idx::kHeading) = heading_variance;
  next_p(idx::kSpeed, idx::kSpeed) = variance / (dt * dt);
  if (filter_->reset(next, next_p) == FilterOutcome::kApplied) {
    heading_known_ = true;
    ++heading_fits_;
    travel_.clear();
  }
}

void KleemanIekf::remember(const kleeman::SlotPulse& pulse) {
  window_.push_back(pulse);
  const auto span =
      static_cast<std::int64_t>(std::max(params_.startup_cycles, params_.heading_fit_cycles) * order_.size());
  while (!window_.empty() && window_.front().slot <= pulse.slot - span) window_.pop_front();
}

InputResult KleemanIekf::track(const PulseArrivalSample& p, double arrival_s) {
  const State& x = filter_->state();
  const std::optional<kleeman::PulseSlot> slot =
      kleeman::slot_of_pulse(arrival_s, x(idx::kFireTime), x(idx::kCycle), max_flight_s_);
  if (!slot || slot->kind == kleeman::PulseSlot::Kind::kTooFarAhead) {
    // The filter's cycle is far off the pulses' (or they stopped for long): start again.
    if (++consecutive_far_ >= 3) lose();
    return InputResult::rejected(Rejection::kPulseTooFarAhead);
  }
  consecutive_far_ = 0;
  if (slot->kind == kleeman::PulseSlot::Kind::kPast) return InputResult::rejected(Rejection::kPulseLate);
  if (slot->kind == kleeman::PulseSlot::Kind::kBetweenSlots) return InputResult::rejected(Rejection::kPulseBetweenSlots);
  const std::int64_t pulse_slot = slot_index_ + slot->slots_ahead;
  if (firing_->heard(pulse_slot, p.mark == PulseMark::kDouble) == kleeman::FiringOrder::Pulse::kOutOfOrder) {
    return InputResult::rejected(Rejection::kPulseLate);
  }
  const std::uint32_t id = *firing_->beacon_of(pulse_slot);
  const FilterOutcome advanced = advance_slots(slot->slots_ahead);
  if (advanced != FilterOutcome::kApplied) return InputResult::of(advanced);

  const double sigma = slots_since_start_ < params_.startup_slots ? params_.startup_arrival_sigma_s : params_.arrival_sigma_s;
  const ArrivalTimeModel model(beacon(id)->position_map_m, receivers_.receiver_height_m, sigma * sigma,
                               kleeman::arrival_time_index());
  const UpdateResult result = filter_->update(model, ArrivalTimeModel::Vector(arrival_s), nis_gate_);
  switch (result.outcome) {
    case FilterOutcome::kApplied:
      consecutive_gated_ = 0;
      remember({pulse_slot, arrival_s, id, beacon(id)->position_map_m});
      corrected(std::max(p.stamp_ns, now_ns().value_or(p.stamp_ns)));
      refit_heading();
      return InputResult::ok();
    case FilterOutcome::kGated:
      if (++consecutive_gated_ >= params_.lost_after_gated) lose();
      return InputResult::rejected(Rejection::kGatedNis);
    default:
      return InputResult::of(result.outcome);
  }
}

// The heading is only observable by moving (eq. 15): while the filter's is unknown (the robot
// stood still since start-up), the last cycles' pulses, once the robot moved, give it by the
// start-up fit, and the filter's pose takes it.
void KleemanIekf::refit_heading() {
  const Covariance& p = filter_->covariance();
  if (!params_.dead_reckoning || heading_known_) return;
  const auto span = static_cast<std::int64_t>(params_.heading_fit_cycles * order_.size());
  if (window_.back().slot - window_.front().slot + 1 < span) return;
  const State& x = filter_->state();
  kleeman::StartupFitSettings settings = fit_settings();
  settings.heading_observed_after_m = params_.heading_fit_min_travel_m;
  settings.speed_of_sound_mps = x(idx::kSpeedOfSound);
  settings.speed_of_sound_sigma_mps = std::sqrt(p(idx::kSpeedOfSound, idx::kSpeedOfSound));
  settings.cycle_s = x(idx::kCycle);
  settings.cycle_sigma_s = std::sqrt(p(idx::kCycle, idx::kCycle));
  const auto first = std::find_if(window_.begin(), window_.end(), [&](const kleeman::SlotPulse& w) {
    return w.slot > window_.back().slot - span;
  });
  // Not before the robot travelled far enough in the window (the fit would find no heading).
  const kleeman::DeadReckoning travelled = track_.between(first->arrival_s, window_.back().arrival_s);
  if (std::hypot(travelled.forward_m, travelled.left_m) < params_.heading_fit_min_travel_m) return;
  const kleeman::StartupFit fit = fit_startup({first, window_.end()}, &track_, settings, x(idx::kHeading));
  if (!fit.ok || !fit.heading_observed) return;
  const FittedPose pose = pose_from_fit(fit, x(idx::kFireTime));
  const double ok_variance = params_.max_ok_heading_sigma_rad * params_.max_ok_heading_sigma_rad;
  if (!(pose.covariance(2, 2) < 0.25 * ok_variance)) return;
  State next = x;
  next(idx::kX) = pose.pose.x();
  next(idx::kY) = pose.pose.y();
  next(idx::kHeading) = pose.pose.z();
  Covariance next_p = p;
  const Eigen::Index pose_at[3] = {idx::kX, idx::kY, idx::kHeading};
  for (const Eigen::Index r : pose_at) {
    next_p.row(r).setZero();
    next_p.col(r).setZero();
  }
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) next_p(pose_at[r], pose_at[q]) = pose.covariance(r, q);
  if (filter_->reset(next, next_p) == FilterOutcome::kApplied) {
    ++heading_fits_;
    know_heading();
  }
}

void KleemanIekf::know_heading() {
  if (heading_known_) return;
  heading_known_ = true;
  State x = filter_->state();
  Covariance p = filter_->covariance();
  const double period = x(idx::kCycle);
  const kleeman::DeadReckoning d = track_.between(x(idx::kFireTime) - period, x(idx::kFireTime));
  x(idx::kSpeed) = d.distance_m / period;
  p.row(idx::kSpeed).setZero();
  p.col(idx::kSpeed).setZero();
  p(idx::kSpeed, idx::kSpeed) =
      d.distance_variance / (period * period) + params_.speed_sigma_mps * params_.speed_sigma_mps;
  filter_->reset(x, p);
}

EstimatorBase::PoseBelief KleemanIekf::pose_belief() const {
  const State& x = filter_->state();
  const Covariance& p = filter_->covariance();
  // From the filter's slot (its firing time t0) to the newest odometry.
  const double tau = std::max(0.0, seconds(*now_ns()) - x(idx::kFireTime));
  const double c = std::cos(x(idx::kHeading)), s = std::sin(x(idx::kHeading));
  double forward = 0.0, left = 0.0, dtheta = 0.0;
  Mat<3, kleeman::kStateSize> j = Mat<3, kleeman::kStateSize>::Zero();
  Eigen::Vector3d motion_variance = Eigen::Vector3d::Zero();
  if (params_.dead_reckoning) {
    const kleeman::DeadReckoning d = track_.between(x(idx::kFireTime), x(idx::kFireTime) + tau);
    forward = d.forward_m;
    left = d.left_m;
    dtheta = d.dtheta_rad;
    motion_variance << d.distance_variance, d.distance_variance, d.dtheta_variance;
  } else {
    forward = x(idx::kSpeed) * tau;  // eq. 15 over the part of a slot
    j(0, idx::kSpeed) = c * tau;
    j(1, idx::kSpeed) = s * tau;
    const double turn = params_.turn_rate_sigma_radps * tau;
    motion_variance(2) = turn * turn;
  }
  j(0, idx::kX) = 1.0;
  j(1, idx::kY) = 1.0;
  j(2, idx::kHeading) = 1.0;
  j(0, idx::kHeading) = -s * forward - c * left;
  j(1, idx::kHeading) = c * forward - s * left;
  PoseBelief belief;
  belief.pose_map_base = Pose2(x(idx::kX) + c * forward - s * left, x(idx::kY) + s * forward + c * left,
                               wrap_angle_rad(x(idx::kHeading) + dtheta));
  belief.covariance = j * p * j.transpose();
  belief.covariance += motion_variance.asDiagonal();
  belief.covariance = 0.5 * (belief.covariance + belief.covariance.transpose()).eval();
  return belief;
}

StartupWait KleemanIekf::waiting_for() const {
  if (!firing_) {
    return {StartupCondition::kFixFailed, 0.0, 0.0,
            "the marked beacon " + std::to_string(params_.marked_beacon_id) + " is not in the beacon map"};
  }
  if (last_fit_failure_ && !sync_arrival_s_) return *last_fit_failure_;
  if (!sync_arrival_s_) return {StartupCondition::kNoDoubleBurst, 0.0, 1.0, {}};
  const double needed = static_cast<double>(params_.startup_cycles * order_.size() + 1);
  const double heard = window_.empty() ? 0.0 : static_cast<double>(window_.back().slot + 1);
  return {StartupCondition::kTooFewRanges, heard, needed, "slots of pulse arrivals for the start-up fit"};
}

bool KleemanIekf::suspect() const {
  if (!filter_) return false;
  const double heading_variance = filter_->covariance()(idx::kHeading, idx::kHeading);
  return consecutive_gated_ >= 3 ||
         heading_variance > params_.max_ok_heading_sigma_rad * params_.max_ok_heading_sigma_rad;
}

std::vector<Estimator::StateValue> KleemanIekf::state_values() const {
  if (!filter_ || !has_pose()) return {};
  const State& x = filter_->state();
  const Covariance& p = filter_->covariance();
  const auto value = [&](const char* name, Eigen::Index i) { return StateValue{name, x(i), std::sqrt(p(i, i))}; };
  return {value("speed_of_sound_mps", idx::kSpeedOfSound), value("cycle_s", idx::kCycle), value("speed_mps", idx::kSpeed)};
}

std::optional<kleeman::State> KleemanIekf::filter_state() const {
  if (!filter_) return std::nullopt;
  return filter_->state();
}

std::optional<kleeman::Covariance> KleemanIekf::filter_covariance() const {
  if (!filter_) return std::nullopt;
  return filter_->covariance();
}

namespace {
BEACONLOC_REGISTER_ESTIMATOR("kleeman_iekf",
                             "seed 002: IEKF on [x, y, v, theta, T, t0, s] over raw pulse arrival times, "
                             "beacons named by their firing order, speed of sound and cycle estimated",
                             "seed002_kleeman.yaml",
                             [](const EstimatorConfig& config) { return std::make_unique<KleemanIekf>(config); });
}  // namespace

}  // namespace beaconloc
