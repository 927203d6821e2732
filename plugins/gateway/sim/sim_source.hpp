#pragma once
// The simulated source, deterministic by seed. Beacon firings in slots: the TOF of each
// receiver that hears the pulse (in range and in the beacon's beam), with the robot moving
// during the flight, range and arrival-time noise, and echoes; wheel odometry at its period with
// speed-proportional noise and systematic wheel-radius / wheel-base errors; laser scans ray cast
// on the map. Ground truth comes with every odometry sample.
#include <cstdint>
#include <map>
#include <queue>
#include <random>
#include <vector>

#include "scenario.hpp"
#include "source.hpp"

namespace beaconloc::sim {

class SimSource final : public Source {
 public:
  SimSource(Scenario scenario, std::uint64_t seed);
  void advance(StampNs until_ns, std::vector<SourceEvent>& out) override;
  bool exhausted() const override { return false; }
  bool finite() const override { return false; }  // a scenario can be run for any duration
  BeaconMap beacon_map() const override { return BeaconMap(scenario_.beacon_list()); }
  ReceiverArray receivers() const override { return scenario_.receivers; }
  StampNs first_stamp_ns() const override { return 0; }
  StampNs last_stamp_ns() const override { return s_to_ns(scenario_.duration_s); }
  bool relative_stamps() const override { return true; }
  std::string describe() const override { return "scenario " + scenario_.name; }
  BeaconInput beacon_input() const override {
    return scenario_.radio_sync ? BeaconInput::kRawTof : BeaconInput::kPulseArrivals;
  }
  const Scenario& scenario() const { return scenario_; }
  // Selective activation (seed 004 Sec. 3): the beacons to fire from the next slot on, each in
  // turn in id order (after the last one fired), instead of the scenario's firing order; nullopt
  // returns to the firing order. Ids the scenario lacks are never fired; an empty plan is the
  // firing order (a robot is never left blind).
  // Only where each pulse names its beacon (radio, identified): beacons heard without an id are
  // named by their place in the firing order (seed 002's cycle), which a plan would break.
  bool honours_firing_plan() const override { return scenario_.radio_sync && scenario_.identified; }
  StampNs slot_period_ns() const override { return scenario_.slot_period_ns; }
  void set_firing_plan(std::optional<std::vector<std::uint32_t>> beacon_ids) override;
  std::vector<Firing> take_firings() override {
    std::vector<Firing> out;
    out.swap(firings_);
    return out;
  }
  struct FiringCounts {
    std::uint64_t fired = 0;  // slots in which a beacon fired
    std::uint64_t heard = 0;  // of those, slots in which some receiver heard it
  };
  FiringCounts firing_counts() const { return counts_; }

 private:
  void fire(StampNs fire_ns);
  std::uint32_t next_beacon();
  SourceEvent odometry_at(StampNs stamp_ns);
  SourceEvent scan_at(StampNs stamp_ns);
  double normal() { return unit_normal_(rng_); }
  double uniform() { return unit_uniform_(rng_); }

  struct Later {
    bool operator()(const SourceEvent& a, const SourceEvent& b) const {
      return a.stamp_ns != b.stamp_ns ? a.stamp_ns > b.stamp_ns
                                      : a.tof.sequence_number > b.tof.sequence_number;
    }
  };
  Scenario scenario_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
  std::uniform_real_distribution<double> unit_uniform_{0.0, 1.0};
  StampNs next_odometry_ns_;
  StampNs next_fire_ns_;
  StampNs next_scan_ns_;
  std::uint64_t slot_ = 0;
  std::optional<std::vector<std::uint32_t>> plan_;
  std::optional<std::uint32_t> last_fired_id_;
  FiringCounts counts_;
  // Firings not yet taken, at most kMaxFiringLog (a caller that never takes them keeps the newest).
  static constexpr std::size_t kMaxFiringLog = 4096;
  std::vector<Firing> firings_;
  std::uint64_t tof_sequence_ = 0;
  std::priority_queue<SourceEvent, std::vector<SourceEvent>, Later> pending_tofs_;
  std::map<std::uint32_t, Eigen::Vector2d> group_centres_map_m_;  // for group_coverage_radius_m
  std::vector<double> beam_errors_m_;  // LaserModel::systematic_error_m, per beam; empty: none
};

// Arrival time of a pulse fired at fire_s from `beacon` at the receiver mounted at
// receiver_base_m on a robot moving along `trajectory` (Kleeman, seed 002 eq. 20: the receiver
// keeps moving while the pulse is in flight). Fixed-point iteration; converges since v << c.
double pulse_arrival_s(const Trajectory& trajectory, const Eigen::Vector2d& receiver_base_m,
                       double receiver_z_m, const Eigen::Vector3d& beacon_map_m, double fire_s,
                       double speed_of_sound_mps);

// Whether a receiver at receiver_map_m hears a beacon: slant range within [min, max] and inside
// the cone of half-angle beam_half_angle_rad around the beacon's downward axis.
bool hears(const Scenario& scenario, const Eigen::Vector3d& beacon_map_m,
           const Eigen::Vector3d& receiver_map_m);

}  // namespace beaconloc::sim
