// kleeman_iekf's start-up (issue 15 item 5) and the heading of a robot that stood still: the
// pulses after the first double burst, fitted (startup_fit.hpp); the filter started from the fit
// with its full covariance; the heading (and pose) found by a fit once the robot has travelled.
#include <algorithm>
#include <cmath>

#include "kleeman_iekf/kleeman_iekf.hpp"

namespace beaconloc {

namespace {
using kleeman::Covariance;
using kleeman::State;
namespace idx = kleeman;
using Fit = kleeman::StartupFit::Parameter;
constexpr Eigen::Index at(Fit p) { return static_cast<Eigen::Index>(p); }
}  // namespace

std::int64_t KleemanIekf::startup_slots_needed() const {
  // startup_cycles cycles (standing_startup_cycles while the robot stands), and at least 12
  // slots: a map of few beacons needs more of their cycles for the fit's six unknowns (three of
  // them with priors).
  const int cycles = standing_in_window() ? params_.standing_startup_cycles : params_.startup_cycles;
  return std::max<std::int64_t>(cycles * static_cast<std::int64_t>(order_.size()), 12);
}

// As the fit tells a robot that moved (fit_startup: heading_observed): never further than
// heading_observed_after_m from where it was at the window's first pulse.
bool KleemanIekf::standing_in_window() const {
  if (!params_.dead_reckoning || window_.empty()) return false;  // without odometry it cannot be told
  const double limit_m = fit_settings().heading_observed_after_m;
  return std::all_of(window_.begin(), window_.end(), [&](const kleeman::SlotPulse& p) {
    const kleeman::DeadReckoning d = track_.between(window_.front().arrival_s, p.arrival_s);
    return std::hypot(d.forward_m, d.left_m) < limit_m;
  });
}

// The pulses after the first double burst, numbered by their slot from it with the nominal T (a
// flight shorter than half a slot, checked in set_beacon_map, leaves each in its own), until
// startup_slots_needed() slots are in; then the fit.
InputResult KleemanIekf::collect_startup(const PulseArrivalSample& p, double arrival_s) {
  const bool double_burst = p.mark == PulseMark::kDouble;
  if (!sync_arrival_s_) {
    if (!double_burst) return InputResult::rejected(Rejection::kPulseBeforeDoubleBurst);
    sync_arrival_s_ = arrival_s;
    window_.clear();
  }
  const double slots = (arrival_s - *sync_arrival_s_) / params_.slot_period_s;
  if (!(slots >= -0.5)) return InputResult::rejected(Rejection::kPulseLate);  // before the window began
  const auto n = static_cast<std::int64_t>(order_.size());
  if (slots > static_cast<double>(startup_slots_needed() + n)) {
    // Far past the window (a long silence): start again from this pulse if it can.
    sync_arrival_s_.reset();
    window_.clear();
    return double_burst ? collect_startup(p, arrival_s) : InputResult::rejected(Rejection::kPulseBeforeDoubleBurst);
  }
  const std::int64_t slot = std::llround(slots);
  if (std::abs(slots - static_cast<double>(slot)) * params_.slot_period_s > max_flight_s_) {
    return InputResult::rejected(Rejection::kPulseBetweenSlots);
  }
  if (!window_.empty() && slot < window_.back().slot) return InputResult::rejected(Rejection::kPulseLate);
  if (const InputResult room = count_in_slot(slot); !room.accepted) return room;
  const std::uint32_t marked = static_cast<std::uint32_t>(params_.marked_beacon_id);
  const auto marked_index = std::find(order_.begin(), order_.end(), marked) - order_.begin();
  const std::uint32_t id = order_[static_cast<std::size_t>((marked_index + slot % n) % n)];
  if (double_burst && id != marked) {
    // A double burst where this numbering has another beacon: the first was an echo behind a
    // single burst, or this one is. Start again from this one; the fit's outlier screen and the
    // tracking's gate catch a numbering that is off.
    sync_arrival_s_.reset();
    window_.clear();
    return collect_startup(p, arrival_s);
  }
  window_.push_back({slot, arrival_s, id, beacon(id)->position_map_m});
  if (slot < startup_slots_needed()) return InputResult::ok();

  const kleeman::StartupFit fit =
      fit_startup({window_.begin(), window_.end()}, params_.dead_reckoning ? &track_ : nullptr, fit_settings());
  if (!fit.ok) {
    ++startup_fits_failed_;
    last_fit_failure_ = StartupWait{StartupCondition::kFixFailed, 0.0, 0.0, fit.why_not};
    sync_arrival_s_.reset();  // again from the next double burst
    window_.clear();
    return InputResult::rejected(Rejection::kStartupFitFailed);
  }
  return start_from_fit(fit, p.stamp_ns) ? InputResult::ok() : InputResult::rejected(Rejection::kStartupFitFailed);
}

// The filter's state at the window's last slot from the fit, and P = G C G^T with G the Jacobian
// of that state in the fit's unknowns [x, y, theta, t_first, T, s] (their correlations kept: the
// fit ties the position to s and t0), plus the dead reckoning's own variance from the reference
// to the slot. The dead-reckoned displacement depends on the slot's time, t_first + m T, only
// through the robot's speed over a timing error of microseconds: left out of G.
bool KleemanIekf::start_from_fit(const kleeman::StartupFit& fit, StampNs stamp_ns) {
  const std::int64_t slot = window_.back().slot;
  const double m = static_cast<double>(slot - fit.first_slot);
  const double period = fit.solution(at(Fit::kCycle));
  const double fire_s = fit.solution(at(Fit::kFirstFireTime)) + m * period;
  kleeman::DeadReckoning d;
  if (params_.dead_reckoning && fire_s > fit.reference_s) d = track_.between(fit.reference_s, fire_s);
  const double heading = fit.solution(at(Fit::kHeading));
  const double c = std::cos(heading), s = std::sin(heading);
  State x;
  x(idx::kX) = fit.solution(at(Fit::kX)) + c * d.forward_m - s * d.left_m;
  x(idx::kY) = fit.solution(at(Fit::kY)) + s * d.forward_m + c * d.left_m;
  x(idx::kHeading) = wrap_angle_rad(heading + d.dtheta_rad);
  x(idx::kCycle) = period;
  x(idx::kFireTime) = fire_s;
  x(idx::kSpeedOfSound) = fit.solution(at(Fit::kSpeedOfSound));
  Mat<kleeman::kStateSize, 6> g = Mat<kleeman::kStateSize, 6>::Zero();
  g(idx::kX, at(Fit::kX)) = 1.0;
  g(idx::kX, at(Fit::kHeading)) = -s * d.forward_m - c * d.left_m;
  g(idx::kY, at(Fit::kY)) = 1.0;
  g(idx::kY, at(Fit::kHeading)) = c * d.forward_m - s * d.left_m;
  g(idx::kHeading, at(Fit::kHeading)) = 1.0;
  g(idx::kCycle, at(Fit::kCycle)) = 1.0;
  g(idx::kFireTime, at(Fit::kFirstFireTime)) = 1.0;
  g(idx::kFireTime, at(Fit::kCycle)) = m;
  g(idx::kSpeedOfSound, at(Fit::kSpeedOfSound)) = 1.0;
  Covariance p = g * fit.covariance * g.transpose();
  p(idx::kX, idx::kX) += d.distance_variance_m2;
  p(idx::kY, idx::kY) += d.distance_variance_m2;
  p(idx::kHeading, idx::kHeading) += d.dtheta_variance_rad2;
  // An unobserved heading (the robot stood still) is uniform: no correlation, a half turn's variance.
  if (!fit.heading_observed || p(idx::kHeading, idx::kHeading) > M_PI * M_PI) {
    p.row(idx::kHeading).setZero();
    p.col(idx::kHeading).setZero();
    p(idx::kHeading, idx::kHeading) = M_PI * M_PI;
  }
  heading_known_ = p(idx::kHeading, idx::kHeading) <= heading_ok_variance();
  // The speed: the dead reckoning's over the slot before; carried at 0 until the heading is known.
  x(idx::kSpeed) = 0.0;
  p(idx::kSpeed, idx::kSpeed) = 1.0;  // without dead reckoning: a speed within a few m/s
  if (params_.dead_reckoning) {
    const SpeedMeasurement before = speed_over(track_.between(fire_s - period, fire_s), period);
    x(idx::kSpeed) = before.speed_mps;
    p(idx::kSpeed, idx::kSpeed) = before.variance_m2ps2;
  }
  if (!heading_known_) {
    x(idx::kSpeed) = 0.0;
    p(idx::kSpeed, idx::kSpeed) = 1e-12;
  }
  filter_.emplace(kleeman::state_space(), IteratedEkfOptions{params_.max_iterations, 1e-9});
  if (filter_->reset(x, p) != FilterOutcome::kApplied) {  // a non-finite state or covariance
    filter_.reset();
    ++startup_fits_failed_;
    last_fit_failure_ = StartupWait{StartupCondition::kFixFailed, 0.0, 0.0, "the fit gave a state that is not finite"};
    sync_arrival_s_.reset();
    window_.clear();
    return false;
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
  return true;
}

// The heading is only observable by moving (eq. 15): while the filter's is unknown (the robot
// stood still since start-up), the last heading_fit_cycles cycles of pulses, once the robot has
// travelled heading_fit_min_travel_m in them, are fitted (startup_fit.hpp, with the filter's T and
// s as priors). The filter takes the fitted pose, moved to its slot by the dead reckoning: the
// heading, and the position too, since the filter's own, carried meanwhile as a random walk of
// the travel (heading_known_), lags a robot that drives. Its timing and s stay the filter's, and
// the new pose is not correlated with them (the fit's t_first was free of the filter's t0).
void KleemanIekf::refit_heading() {
  if (!params_.dead_reckoning || heading_known_) return;
  const auto span = static_cast<std::int64_t>(params_.heading_fit_cycles * order_.size());
  if (window_.back().slot - window_.front().slot + 1 < span) return;
  const auto first = std::find_if(window_.begin(), window_.end(), [&](const kleeman::SlotPulse& w) {
    return w.slot > window_.back().slot - span;
  });
  // Not before the robot travelled far enough in the window (the fit would find no heading).
  const kleeman::DeadReckoning travelled = track_.between(first->arrival_s, window_.back().arrival_s);
  if (std::hypot(travelled.forward_m, travelled.left_m) < params_.heading_fit_min_travel_m) return;
  const State& x = filter_->state();
  const Covariance& p = filter_->covariance();
  kleeman::StartupFitSettings settings = fit_settings();
  settings.heading_observed_after_m = params_.heading_fit_min_travel_m;
  settings.speed_of_sound_mps = x(idx::kSpeedOfSound);
  settings.speed_of_sound_sigma_mps = std::sqrt(p(idx::kSpeedOfSound, idx::kSpeedOfSound));
  settings.cycle_s = x(idx::kCycle);
  settings.cycle_sigma_s = std::sqrt(p(idx::kCycle, idx::kCycle));
  const kleeman::StartupFit fit = fit_startup({first, window_.end()}, &track_, settings, x(idx::kHeading));
  if (!fit.ok || !fit.heading_observed || !(x(idx::kFireTime) >= fit.reference_s)) return;
  // The fitted pose at the reference, moved by the dead reckoning to the filter's slot.
  const kleeman::DeadReckoning d = track_.between(fit.reference_s, x(idx::kFireTime));
  const double heading = fit.solution(at(Fit::kHeading));
  const double c = std::cos(heading), s = std::sin(heading);
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();  // d(pose at the slot)/d(x, y, theta at the reference)
  j(0, 2) = -s * d.forward_m - c * d.left_m;
  j(1, 2) = c * d.forward_m - s * d.left_m;
  const Eigen::Index fit_at[3] = {at(Fit::kX), at(Fit::kY), at(Fit::kHeading)};
  Eigen::Matrix3d fitted;
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) fitted(r, q) = fit.covariance(fit_at[r], fit_at[q]);
  Eigen::Matrix3d pose_covariance = j * fitted * j.transpose();
  pose_covariance += Eigen::Vector3d(d.distance_variance_m2, d.distance_variance_m2, d.dtheta_variance_rad2).asDiagonal();
  if (!(pose_covariance(2, 2) < 0.25 * heading_ok_variance())) return;
  State next = x;
  next(idx::kX) = fit.solution(at(Fit::kX)) + c * d.forward_m - s * d.left_m;
  next(idx::kY) = fit.solution(at(Fit::kY)) + s * d.forward_m + c * d.left_m;
  next(idx::kHeading) = wrap_angle_rad(heading + d.dtheta_rad);
  Covariance next_p = p;
  const Eigen::Index pose_at[3] = {idx::kX, idx::kY, idx::kHeading};
  for (const Eigen::Index r : pose_at) {
    next_p.row(r).setZero();
    next_p.col(r).setZero();
  }
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) next_p(pose_at[r], pose_at[q]) = pose_covariance(r, q);
  if (filter_->reset(next, next_p) == FilterOutcome::kApplied) {
    ++heading_fits_;
    know_heading();
  }
}

// Leaves the mode of an unknown heading: v from the dead reckoning over the slot before.
void KleemanIekf::know_heading() {
  heading_known_ = true;
  State x = filter_->state();
  Covariance p = filter_->covariance();
  const double period = x(idx::kCycle);
  const SpeedMeasurement before = speed_over(track_.between(x(idx::kFireTime) - period, x(idx::kFireTime)), period);
  x(idx::kSpeed) = before.speed_mps;
  p.row(idx::kSpeed).setZero();
  p.col(idx::kSpeed).setZero();
  p(idx::kSpeed, idx::kSpeed) = before.variance_m2ps2;
  filter_->reset(x, p);
}

// Without dead reckoning the heading is the direction the beacons see the robot travel: once the
// filter's position moved heading_fit_min_travel_m over at most heading_fit_cycles cycles, the
// heading is that of the displacement and the speed its length over the time, each with the
// variance the two positions give (lateral sigma over the distance).
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
  if (heading_variance > 0.25 * heading_ok_variance()) return;
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

}  // namespace beaconloc
