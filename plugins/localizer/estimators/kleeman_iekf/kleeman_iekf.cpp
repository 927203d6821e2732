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
  p.standing_startup_cycles = in.count("standing_startup_cycles", p.standing_startup_cycles, 1, 20);
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

// Sec. 2: the beacons fire in the order of their numbers (123456123...), one a slot of the
// slot_period_s parameter (the beacon controller's configuration, as the paper's receiver knows
// it). What was tracked against another map starts again.
void KleemanIekf::set_beacon_map(const BeaconMap& map) {
  EstimatorBase::set_beacon_map(map);
  reset_tracking();
  order_.clear();
  Eigen::AlignedBox3d extent;
  for (const Beacon& b : map.beacons()) {
    order_.push_back(b.id);
    extent.extend(b.position_map_m);
  }
  std::sort(order_.begin(), order_.end());
  firing_.reset();
  map_problem_.reset();
  // The longest flight: across the beacons' extent (the robot inside it), down to the receiver,
  // at the slowest sound, and an echo's delay. Past half a slot a pulse could belong to two.
  const Eigen::Vector3d span(extent.sizes().x(), extent.sizes().y(),
                             std::max(std::abs(extent.max().z() - receivers_.receiver_height_m),
                                      std::abs(extent.min().z() - receivers_.receiver_height_m)));
  max_flight_s_ = map.empty() ? 0.0 : span.norm() / kSlowestSoundMps + kEchoAllowanceS;
  const auto marked = static_cast<std::uint32_t>(params_.marked_beacon_id);
  if (map.local_size() > 0) {
    // Seed 003's locally referenced beacons fire in the cycle too, but where they are is unknown:
    // neither their pulses nor the slots' flight bound could be modelled.
    map_problem_ = std::to_string(map.local_size()) + " locally referenced beacon(s): their positions are not known";
  } else if (std::find(order_.begin(), order_.end(), marked) == order_.end()) {
    map_problem_ = "the marked beacon " + std::to_string(marked) + " is not in the beacon map";
  } else if (order_.size() < 3) {
    map_problem_ = std::to_string(order_.size()) + " beacon(s): a position and a firing time need three";
  } else if (max_flight_s_ >= 0.5 * params_.slot_period_s) {
    map_problem_ = "the beacons span " + std::to_string(span.norm()) + " m: a flight of up to " +
                   std::to_string(1e3 * max_flight_s_) + " ms is over half a slot, the slots would be ambiguous";
  } else {
    firing_.emplace(order_, marked);
  }
}

void KleemanIekf::reset_tracking() {
  filter_.reset();
  travel_.clear();
  if (has_pose()) forget_pose();
  window_.clear();
  sync_arrival_s_.reset();
  recent_pulses_.clear();
  counted_slot_ = -1;
  pulses_in_slot_ = 0;
}

const Beacon* KleemanIekf::beacon(std::uint32_t id) const { return map().find(id); }

InputResult KleemanIekf::predict(const OdometrySample& o) {
  const OdometryTimeline::Step step = advance(o);
  if (!step.result.accepted) return step.result;
  if (!epoch_ns_) epoch_ns_ = o.stamp_ns;
  if (step.integrate) track_.add(o, seconds(o.stamp_ns), step.dt_s);
  // A silence: no pulse for as long as the filter may step (kMaxSlotsAhead slots), or a start-up
  // window gone stale. What was held is dropped, so that nothing grows while the beacons are quiet.
  const double now_s = seconds(o.stamp_ns);
  if (filter_ && now_s - filter_->state()(idx::kFireTime) > kleeman::kMaxSlotsAhead * filter_->state()(idx::kCycle)) {
    ++silences_;
    lose();
  } else if (sync_arrival_s_ &&
             now_s - *sync_arrival_s_ > static_cast<double>(startup_slots_needed() + 2 * order_.size()) * params_.slot_period_s) {
    sync_arrival_s_.reset();
    window_.clear();
  }
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
  if (!firing_) return InputResult::rejected(Rejection::kBeaconMapUnusable);  // map_problem_ says why
  // The odometry stamps the pose and carries it between slots (and epoch_ns_ is set with it).
  if (!now_ns() || !epoch_ns_) return InputResult::rejected(Rejection::kRangesWithoutOdometry);
  if (p.stamp_ns < *now_ns() - kMeasurementHorizonNs) return InputResult::rejected(Rejection::kStaleRange);
  if (heard_before(p)) return InputResult::rejected(Rejection::kDuplicatePulse);
  const double arrival_s = seconds(p.stamp_ns);
  return filter_ ? track(p, arrival_s) : collect_startup(p, arrival_s);
}

bool KleemanIekf::heard_before(const PulseArrivalSample& p) {
  constexpr std::size_t kRemembered = 64;  // several cycles of every receiver's pulses
  const std::pair<std::uint32_t, StampNs> key{p.receiver_id, p.stamp_ns};
  if (std::find(recent_pulses_.begin(), recent_pulses_.end(), key) != recent_pulses_.end()) return true;
  recent_pulses_.push_back(key);
  if (recent_pulses_.size() > kRemembered) recent_pulses_.pop_front();
  return false;
}

InputResult KleemanIekf::count_in_slot(std::int64_t slot) {
  if (slot != counted_slot_) {
    counted_slot_ = slot;
    pulses_in_slot_ = 0;
  }
  if (pulses_in_slot_ >= kMaxPulsesPerSlotPerReceiver * static_cast<int>(receivers_.size())) {
    return InputResult::rejected(Rejection::kTooManyPulsesInSlot);
  }
  ++pulses_in_slot_;
  return InputResult::ok();
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
  s.min_beacons = 3;  // set_beacon_map refuses fewer
  return s;
}

void KleemanIekf::lose() {
  reset_tracking();
  ++losses_;
}

FilterOutcome KleemanIekf::advance_slots(std::int64_t slots) {
  for (std::int64_t i = 0; i < slots; ++i) {
    const State& x = filter_->state();
    const double period = x(idx::kCycle), from = x(idx::kFireTime);
    double dtheta = 0.0, dtheta_variance_rad2 = 0.0, unknown_travel_variance = 0.0;
    kleeman::SlotNoise noise = params_.noise;
    if (params_.dead_reckoning) {
      const kleeman::DeadReckoning d = track_.between(from, from + period);
      if (heading_known_) {
        // Eq. 25: the slot's mean dead-reckoned speed measures v, the speed over the slot.
        const SpeedMeasurement z = speed_over(d, period);
        Mat<1, kleeman::kStateSize> h = Mat<1, kleeman::kStateSize>::Zero();
        h(0, idx::kSpeed) = 1.0;
        const UpdateResult speed =
            filter_->update(LinearModel<1, kleeman::kStateSize>(h, Mat<1, 1>(z.variance_m2ps2)), Vec<1>(z.speed_mps));
        if (!speed.applied()) return speed.outcome;
      } else {
        // The heading unknown: no move along it (v = 0), the travel as noise.
        unknown_travel_variance = d.distance_m * d.distance_m + d.distance_variance_m2;
        noise.speed_mps = 0.0;  // v stays 0: no pulse may find a speed along an unknown heading
      }
      dtheta = d.dtheta_rad;  // eq. 24
      dtheta_variance_rad2 = dtheta_input_variance(d);
    } else if (!heading_known_) {
      // No dead reckoning and no heading yet: a random walk of the robot's top speed, v = 0.
      const double step = params_.unknown_speed_mps * period;
      unknown_travel_variance = step * step;
      noise.speed_mps = 0.0;
    } else {
      const double turn = params_.turn_rate_sigma_radps * period;
      dtheta_variance_rad2 = turn * turn;
    }
    const PredictResult predicted =
        filter_->predict(kleeman::SlotTransition(dtheta_variance_rad2, noise, unknown_travel_variance), Vec<1>(dtheta), period);
    if (!predicted.applied()) return predicted.outcome;
    ++slot_index_;
    ++slots_since_start_;
    if (!params_.dead_reckoning && !heading_known_) heading_from_travel();
  }
  return FilterOutcome::kApplied;
}

KleemanIekf::SpeedMeasurement KleemanIekf::speed_over(const kleeman::DeadReckoning& d, double period_s) const {
  return {d.distance_m / period_s,
          d.distance_variance_m2 / (period_s * period_s) + params_.speed_sigma_mps * params_.speed_sigma_mps};
}

double KleemanIekf::dtheta_input_variance(const kleeman::DeadReckoning& d) const {
  const double model_sigma = params_.heading_offset_sigma_rad + params_.heading_fraction * std::abs(d.dtheta_rad);
  return d.dtheta_variance_rad2 + model_sigma * model_sigma;
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
  if (!firing_->synchronized()) return InputResult::rejected(Rejection::kPulseBeforeDoubleBurst);
  if (pulse_slot < counted_slot_) return InputResult::rejected(Rejection::kPulseLate);
  if (const InputResult room = count_in_slot(pulse_slot); !room.accepted) return room;
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
    motion_variance << d.distance_variance_m2, d.distance_variance_m2, d.dtheta_variance_rad2;
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
  if (!firing_) return {StartupCondition::kFixFailed, 0.0, 0.0, map_problem_.value_or("no beacon map")};
  if (last_fit_failure_ && !sync_arrival_s_) return *last_fit_failure_;
  if (!sync_arrival_s_) return {StartupCondition::kNoDoubleBurst, 0.0, 1.0, {}};
  const double needed = static_cast<double>(startup_slots_needed() + 1);
  const double heard = window_.empty() ? 0.0 : static_cast<double>(window_.back().slot + 1);
  return {StartupCondition::kTooFewRanges, heard, needed, "slots of pulse arrivals for the start-up fit"};
}

bool KleemanIekf::suspect() const {
  if (!filter_) return false;
  const double heading_variance = filter_->covariance()(idx::kHeading, idx::kHeading);
  return consecutive_gated_ >= 3 || heading_variance > heading_ok_variance();
}

std::vector<Estimator::StateValue> KleemanIekf::state_values() const {
  if (!filter_ || !has_pose()) return {};
  const State& x = filter_->state();
  const Covariance& p = filter_->covariance();
  const auto value = [&](const char* name, Eigen::Index i) { return StateValue{name, x(i), std::sqrt(p(i, i))}; };
  std::vector<StateValue> out{value("speed_of_sound_mps", idx::kSpeedOfSound), value("cycle_s", idx::kCycle)};
  // While the heading is unknown v is held at 0 (heading_known_): not an estimate of the speed.
  if (heading_known_) out.push_back(value("speed_mps", idx::kSpeed));
  return out;
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
