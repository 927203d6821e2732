#pragma once
// A simulated world: ceiling beacons, the robot's receivers and wheels, a path, and the noise
// of each sensor. The YAML scenario files of the simulator issue fill this same structure.
#include <cstdint>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/receiver_array.hpp"
#include "beaconloc/core/time.hpp"
#include "trajectory.hpp"

namespace beaconloc::sim {

struct Scenario {
  std::string name;
  std::vector<Beacon> beacons;
  std::vector<std::uint32_t> firing_order;  // beacon ids, one per slot, cycled
  ReceiverArray receivers;
  double wheel_base_m = 0.33;
  double odometry_k_v_m = 4e-4;                      // seed 000: sigma_v^2 = k_v |v| / dT per wheel
  double range_sigma_m = 0.01;                       // seed 000: sigma_dd
  double temperature_c = 22.0;                       // air temperature, reported by the beacons
  double max_range_m = 5.0;                          // a receiver hears a beacon up to this slant range
  StampNs slot_period_ns = 200 * kNsPerMillisecond;  // 5 Hz firing slots
  StampNs first_slot_ns = 50 * kNsPerMillisecond;
  StampNs odometry_period_ns = 10 * kNsPerMillisecond;  // 100 Hz
  Trajectory trajectory;
};

// The built-in scenario `demo` and the tests run: seed 000's setup (six Txs at z_T = 2.011 m,
// three Rxs on a 0.19 m circle, sigma_dd = 0.01 m, k_v = 4e-4 m, 0.34 m/s, 100 Hz odometry,
// 200 ms slots) on a 2 m x 1.2 m stadium loop under a 3 x 2 beacon grid.
Scenario default_scenario();

}  // namespace beaconloc::sim
