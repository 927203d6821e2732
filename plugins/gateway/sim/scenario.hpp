#pragma once
// A simulated world: ceiling beacons, the robot's receivers and wheels, a path, the beacon
// system's timing and physics, and optionally a map and a laser. Loaded from the YAML files of
// examples/scenarios/ (schema in its README) or built in (default_scenario).
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/occupancy_grid.hpp"
#include "beaconloc/core/receiver_array.hpp"
#include "beaconloc/core/time.hpp"
#include "laser_world.hpp"
#include "trajectory.hpp"

namespace beaconloc::sim {

struct EchoModel {
  double probability = 0.0;       // per firing and receiver: the first arrival is an echo
  double min_extra_path_m = 0.3;  // extra path of the echo, uniform in [min, max]
  double max_extra_path_m = 3.0;
};

// Faults injected into the world (sim/faults.hpp gives them from text).
struct Faults {
  std::map<std::uint32_t, StampNs> beacon_dies_at_ns;             // beacon id -> fires no more from
  std::vector<std::pair<StampNs, StampNs>> tof_outages_ns;        // [from, to): no TOF published
  bool silences(std::uint32_t beacon_id, StampNs fire_ns) const;  // dead beacon or outage
};

struct LaserModel {
  int beams = 19;
  double fov_rad = M_PI;
  StampNs period_ns = 22 * kNsPerMillisecond;
  double range_sigma_m = 0.1;       // statistical error: drawn for every reading
  double systematic_error_m = 0.0;  // each beam's own fixed error, uniform in [-e, e], drawn once a run
  LaserSpot spot;                   // ideal by default: the surface on the beam's axis
  double max_range_m = 8.0;
  Pose2 mount_base = Pose2::Zero();  // in the robot frame
};

struct Scenario {
  std::string name = "default";
  std::string description;
  std::uint64_t seed = 1;
  double duration_s = 20.0;
  // Poses before this time are not scored (the paper's own start of scoring: seed 002 scores its
  // path error from 20 s); the accuracy commands' settling time counts as well.
  double score_from_s = 0.0;

  std::vector<Beacon> beacons;  // every beacon at its true map position (the simulator's truth)
  // Seed 003: the locally referenced beacon groups, each with its frame's true pose in the map
  // (x, y, yaw). Their beacons are given to the participants in their group's frame only
  // (beacon_list()); every other group is globally referenced.
  std::map<std::uint32_t, Pose2> local_group_frames_map;
  // The beacon map the gateway publishes (and the offline runs hand over): the globally
  // referenced beacons at their map positions, the locally referenced ones in their group's frame.
  BeaconList beacon_list() const;
  // Each beacon group's centre on the floor: the mean of its beacons' (x, y), group 0 included.
  std::map<std::uint32_t, Eigen::Vector2d> group_centres_map_m() const;
  // Whether the group whose centre is nearest (x_map_m, y_map_m) is locally referenced: where a
  // robot localizes against calibrated beacons.
  bool nearest_group_is_local(double x_map_m, double y_map_m) const;
  // Beacon system.
  std::vector<std::uint32_t> firing_order;           // beacon ids, one per slot, cycled
  StampNs slot_period_ns = 200 * kNsPerMillisecond;  // 5 Hz firing slots
  StampNs first_slot_ns = 50 * kNsPerMillisecond;
  bool identified = true;                         // false: anonymous pulses
  // false: the beacons send no radio message (seed 002): no firing time, no temperature; the
  // gateway publishes pulse arrivals (PulseArrival), with the double-burst mark of the marked
  // beacon, instead of times of flight.
  bool radio_sync = true;
  std::optional<std::uint32_t> marked_beacon_id;  // recognisable even when anonymous
  double range_sigma_m = 0.01;                    // seed 000: sigma_dd
  double tof_sigma_s = 0.0;                       // seed 002: arrival-time noise
  // The ranging system's calibration error: a flight path d reads as range_scale * d +
  // range_bias_m (a radio's clock rate and delay, as CMU Plaza's read 6.9 % long).
  double range_scale = 1.0;
  double range_bias_m = 0.0;
  double min_range_m = 0.0;                       // a receiver hears slant ranges in [min, max]
  double max_range_m = 5.0;
  double beam_half_angle_rad = M_PI / 2;         // cone around the beacon's downward axis
  // Those three as every beacon's reach (the beacon map carries it: BeaconList::reach).
  BeaconReach reach() const { return {min_range_m, max_range_m, beam_half_angle_rad}; }
  // Seed 003 Sec. 2: a beacon group (ULPS, group != 0) covers a circle of this radius on the
  // floor around its centre: a receiver hears the group's beacons within it and none outside
  // (on top of the range and beam limits above). None: each beacon's own limits alone.
  std::optional<double> group_coverage_radius_m;
  double temperature_c = 22.0;                   // true air temperature
  std::optional<double> reported_temperature_c;  // what beacons report; default: the truth
  EchoModel echo;
  Faults faults;

  // Robot.
  ReceiverArray receivers;
  double wheel_base_m = 0.33;
  StampNs odometry_period_ns = 10 * kNsPerMillisecond;  // 100 Hz
  double odometry_k_v_m = 4e-4;                         // seed 000: sigma_v^2 = k_v |v| / dT per wheel
  double wheel_radius_error_right = 0.0;                // measured wheel speed = true * (1 + error)
  double wheel_radius_error_left = 0.0;
  double wheel_base_error = 0.0;  // reported B_w = true * (1 + error)
  // Seed 001 eq. 6 instead of k_v: per odometry sample, noise on (v, w) with variances
  // alpha_1 v^2 + alpha_2 w^2 and alpha_3 v^2 + alpha_4 w^2.
  std::optional<std::array<double, 4>> odometry_alpha;

  Trajectory trajectory;
  std::optional<OccupancyGrid> map;
  // The world the laser sees when it differs from the map (unmapped obstacles, or the room's
  // surfaces on a finer grid than the map's); none: the map.
  std::optional<OccupancyGrid> world;
  std::vector<Walker> people;  // moving, in no map: only the laser sees them
  std::optional<LaserModel> laser;
};

// The scenario's noise models, as the simulator draws them (sim_source.cpp) and the pose bound
// takes them (plugins/eval/offline/pose_bound.hpp): one definition for both.
// Seed 001 eq. 6: the variances of (v, w) per odometry sample, alpha_1 v^2 + alpha_2 w^2 and
// alpha_3 v^2 + alpha_4 w^2.
Eigen::Vector2d alpha_velocity_variances(const std::array<double, 4>& alpha, double linear_mps, double angular_radps);
// The covariance of the wheel speeds [v_R, v_L] one odometry sample of dt_s carries, at the wheel
// speeds given: seed 000's sigma_v^2 = k_v |v| / dT per wheel, or seed 001's alpha model carried
// to the wheels by [v_R, v_L] = [[1, B/2], [1, -B/2]] [v, w].
Eigen::Matrix2d wheel_velocity_covariance(const Scenario& scenario, double right_mps, double left_mps,
                                          double wheel_base_m, double dt_s);
// The variance of a range from one time of flight: the range noise and the arrival-time noise
// (times the speed of sound) are drawn independently.
double range_variance_m2(const Scenario& scenario);

// The built-in scenario `demo` and the tests run: seed 000's setup (six Txs at z_T = 2.011 m,
// three Rxs on a 0.19 m circle, sigma_dd = 0.01 m, k_v = 4e-4 m, 0.34 m/s, 100 Hz odometry,
// 200 ms slots) on a 2 m x 1.2 m stadium loop under a 3 x 2 beacon grid
// (examples/scenarios/default.yaml describes the same world).
Scenario default_scenario();

}  // namespace beaconloc::sim
