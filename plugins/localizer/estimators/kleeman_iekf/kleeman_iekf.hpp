#pragma once
// kleeman_iekf: seed 002 (L. Kleeman, "Optimal Estimation of Position and Heading for Mobile
// Robots Using Ultrasonic Beacons and Dead-reckoning"). Six beacons fire in a cycle with no
// radio message; the robot hears pulse arrival times only (PulseArrival), beacon 1 marked by a
// double burst. One iterated EKF (Sec. 3.4; core/filters/iterated_ekf.hpp) on the state of
// eq. 14, [x, y, v, theta, T, t0, s], stepped once per beacon slot (eq. 15-16,
// slot_transition.hpp) with the dead-reckoned heading change as its input (eq. 24) and the
// dead-reckoned speed as a measurement (eq. 25), updated by each pulse's arrival time (eq. 21,
// core/models/arrival_time_model.hpp) in Joseph form (eq. 11).
//  - The pulse's slot from the filter's own t0 and T, its beacon from the firing order counted
//    from the last double burst (firing_order.hpp); missed pulses and extra ones counted.
//  - Echoes (Sec. 3.9) gated on the innovation at a chi-square probability (echo_gate_probability;
//    the paper's 3 ms at its 0.2 ms is 15 sigma), with a larger arrival-time variance for the
//    first slots after start-up, as the paper's initialisation has.
//  - Start-up from the arrival times themselves (startup_fit.hpp) instead of the paper's 15 s
//    standing still: a few cycles after the first double burst; a robot that stood still has its
//    heading found the same way once it has moved (the heading is only observable by moving).
//  - Lost, back to start-up: when the cycle's numbering no longer fits (lost_after_gated pulses
//    gated in a row, or three pulses in a row further ahead than the filter can step), and when
//    no pulse came for as long as it can step (a silence).
//  - Refused by reason: a duplicate pulse (a receiver's arrival stamp heard already), more than
//    kMaxPulsesPerSlotPerReceiver in a slot (a flood), a map it cannot number (no marked beacon,
//    fewer than three beacons, or flights over half a slot: the slots would be ambiguous).
#include <deque>
#include <optional>

#include "beaconloc/core/estimator_base.hpp"
#include "beaconloc/core/filters/iterated_ekf.hpp"
#include "kleeman_iekf/firing_order.hpp"
#include "kleeman_iekf/kleeman_state.hpp"
#include "kleeman_iekf/odometry_track.hpp"
#include "kleeman_iekf/slot_transition.hpp"
#include "kleeman_iekf/startup_fit.hpp"

namespace beaconloc {

struct KleemanParameters {
  double slot_period_s = 0.15;              // Sec. 2: beacons fired 150 ms apart (the nominal T)
  double slot_period_sigma_s = 1e-3;        // how well the nominal is known
  int marked_beacon_id = 1;                 // Sec. 2: beacon 1 fires the double burst
  double arrival_sigma_s = 2e-4;            // Sec. 2, 3.11: 0.2 ms
  double startup_arrival_sigma_s = 1e-3;    // Sec. 3.9: "a high variance" during initialisation
  int startup_slots = 12;                   // slots after start-up with the high variance
  // Sec. 4: the speed of sound starts from a nominal with 5 m/s standard deviation; the nominal
  // is 20 C's by seed 000's formula (nothing reports the air's temperature).
  double initial_speed_of_sound_mps = 343.3;
  double initial_speed_of_sound_sigma_mps = 5.0;
  // Echo gate (Sec. 3.9): the chance that a direct pulse is refused.
  double echo_gate_probability = 1e-4;
  int startup_cycles = 2;                   // cycles of pulses the start-up fit takes
  // ... while the robot stands still in them: standing costs the fit no dead-reckoning error,
  // and each beacon heard again tells its echoes. The fit drops an echo only while 8 pulses
  // remain, and a beacon echoed in both of two cycles looks consistent: with 30 % echoes seed 6
  // started 0.86 m off and took 40 s to come back (ten seeds 0.071 +- 0.048 m E_p RMS, against
  // 0.054 +- 0.007 m with three; clean runs unchanged: docs/robustness.md). The paper itself
  // starts from 15 s standing still (Sec. 4).
  int standing_startup_cycles = 3;
  // The heading of a robot that stood still at start-up: fitted over this many cycles once the
  // robot has travelled heading_fit_min_travel_m in them (7 cm of noise per pulse at 0.2 ms
  // needs half a metre for a heading to a few degrees).
  int heading_fit_cycles = 4;
  double heading_fit_min_travel_m = 0.5;
  // Without dead reckoning, until the heading is found: the robot's top speed, as a random walk.
  double unknown_speed_mps = 0.3;
  double startup_outlier_gate_s = 1.5e-3;   // a pulse the fit misses by more is an echo
  bool dead_reckoning = true;               // Sec. 4's closing comparison: false runs without it
  // Sec. 3.10: the heading input's standard deviation, an offset plus a fraction of |dtheta|.
  double heading_offset_sigma_rad = 0.002;
  double heading_fraction = 0.05;
  double speed_sigma_mps = 0.01;            // floor on the dead-reckoned speed's (eq. 25)
  double turn_rate_sigma_radps = 0.5;       // without dead reckoning: the turn a slot may hold
  kleeman::SlotNoise noise;
  int max_iterations = 10;                  // IEKF re-linearizations per pulse
  double max_odometry_gap_s = 0.5;
  // A pose whose heading is less certain than this is degraded (not yet found by moving).
  double max_ok_heading_sigma_rad = 0.35;
  int lost_after_gated = 12;                // pulses refused in a row: two cycles

  static KleemanParameters from(const EstimatorConfig& config);
};

class KleemanIekf final : public EstimatorBase {
 public:
  explicit KleemanIekf(const EstimatorConfig& config);
  KleemanIekf(const EstimatorConfig& config, const KleemanParameters& params);
  std::string name() const override { return "kleeman_iekf"; }
  BeaconInput beacon_input() const override { return BeaconInput::kPulseArrivals; }
  void set_beacon_map(const BeaconMap& map) override;
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  InputResult update_pulse(const PulseArrivalSample& pulse) override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<KleemanIekf>(*this); }
  // speed_of_sound_mps, cycle_s (T) and speed_mps (v) of eq. 14, while tracking.
  std::vector<StateValue> state_values() const override;

  // The filter's state and covariance (eq. 14) while it has one; its times from epoch_ns().
  std::optional<kleeman::State> filter_state() const;
  std::optional<kleeman::Covariance> filter_covariance() const;
  std::optional<StampNs> epoch_ns() const { return epoch_ns_; }
  const kleeman::FiringOrder* firing_order() const { return firing_ ? &*firing_ : nullptr; }
  // The beacon that fired in the filter's current slot (t0), as it numbers them; nullopt before.
  std::optional<std::uint32_t> current_beacon() const {
    return filter_ && firing_ ? firing_->beacon_of(slot_index_) : std::nullopt;
  }
  std::uint64_t startup_fits_failed() const { return startup_fits_failed_; }
  // Pulses one receiver may give in one slot: the direct one and a few echoes. More is a flood.
  static constexpr int kMaxPulsesPerSlotPerReceiver = 4;
  std::uint64_t heading_fits() const { return heading_fits_; }
  std::uint64_t losses() const { return losses_; }
  std::uint64_t silences() const { return silences_; }  // losses for want of pulses

 private:
  PoseBelief pose_belief() const override;
  StartupWait waiting_for() const override;
  bool suspect() const override;

  double seconds(StampNs stamp_ns) const { return 1e-9 * static_cast<double>(stamp_ns - *epoch_ns_); }
  InputResult collect_startup(const PulseArrivalSample& pulse, double arrival_s);
  InputResult track(const PulseArrivalSample& pulse, double arrival_s);
  FilterOutcome advance_slots(std::int64_t slots);
  void remember(const kleeman::SlotPulse& pulse);
  kleeman::StartupFitSettings fit_settings() const;
  std::int64_t startup_slots_needed() const;
  bool standing_in_window() const;  // the start-up window so far moved the robot less than the fit needs for a heading
  // False (and the filter not started, the failure counted) when the fit's state is not finite.
  bool start_from_fit(const kleeman::StartupFit& fit, StampNs stamp_ns);
  // Counts a pulse in `slot`; too_many_pulses_in_slot past the cap.
  InputResult count_in_slot(std::int64_t slot);
  // A duplicate of a pulse heard lately (same receiver, same arrival stamp).
  bool heard_before(const PulseArrivalSample& pulse);
  // Back to start-up (a map change, or what lose() says).
  void reset_tracking();
  // Eq. 25: the dead-reckoned mean speed over a slot (d, of period_s) as a measurement of v.
  struct SpeedMeasurement {
    double speed_mps = 0.0;
    double variance_m2ps2 = 0.0;
  };
  SpeedMeasurement speed_over(const kleeman::DeadReckoning& d, double period_s) const;
  // Sec. 3.10: the variance of the heading input dtheta (eq. 24): the odometry's, plus an offset
  // and a fraction of the increment, squared.
  double dtheta_input_variance(const kleeman::DeadReckoning& d) const;
  double heading_ok_variance() const { return params_.max_ok_heading_sigma_rad * params_.max_ok_heading_sigma_rad; }
  void refit_heading();
  // Leaves the mode of an unknown heading (heading_known_) with the speed of the dead reckoning.
  void know_heading();
  void heading_from_travel();
  void lose();
  const Beacon* beacon(std::uint32_t id) const;

  KleemanParameters params_;
  ReceiverArray receivers_;
  double nis_gate_ = 0.0;
  double max_flight_s_ = 0.0;  // the longest direct flight across the beacons' extent, and echoes
  std::optional<std::string> map_problem_;  // why the map cannot be numbered (pulses refused)
  std::optional<StampNs> epoch_ns_;
  kleeman::OdometryTrack track_;
  std::optional<kleeman::FiringOrder> firing_;
  std::vector<std::uint32_t> order_;  // the map's beacon ids in firing order
  // Start-up: the first double burst's arrival, and the pulses numbered from its slot.
  std::optional<double> sync_arrival_s_;
  std::deque<kleeman::SlotPulse> window_;  // also, once tracking, the last few cycles (heading fit)
  std::optional<IteratedEkf<kleeman::kStateSize>> filter_;
  std::int64_t slot_index_ = 0;  // the filter's current slot, in the firing order's numbering
  std::int64_t slots_since_start_ = 0;
  // The heading is known (found by the start-up fit or by moving). Until it is, the filter
  // carries the robot at v = 0 with its dead-reckoned travel as position noise, so that no pulse
  // linearizes eq. 15 or eq. 21 about a heading that may be a half turn off; the heading itself
  // follows the dead-reckoned turns (eq. 24) until refit_heading() places it.
  bool heading_known_ = false;
  // Without dead reckoning, the filter's positions while its heading is unknown (one a slot).
  struct TravelPoint {
    double t_s;
    Eigen::Vector2d position_m;
    double variance_m2;  // per axis
  };
  std::deque<TravelPoint> travel_;
  int consecutive_gated_ = 0;
  std::int64_t counted_slot_ = -1;  // the slot pulses_in_slot_ counts (count_in_slot)
  int pulses_in_slot_ = 0;
  std::deque<std::pair<std::uint32_t, StampNs>> recent_pulses_;  // (receiver, stamp) of the last pulses
  int consecutive_far_ = 0;
  std::optional<StartupWait> last_fit_failure_;
  std::uint64_t startup_fits_failed_ = 0;
  std::uint64_t heading_fits_ = 0;
  std::uint64_t losses_ = 0;
  std::uint64_t silences_ = 0;
};

}  // namespace beaconloc
