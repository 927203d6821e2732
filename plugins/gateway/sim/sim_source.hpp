#pragma once
// Deterministic (by seed) sensor stream of a scenario: 100 Hz wheel odometry with seed 000's
// speed-proportional noise, and beacon firings in 200 ms slots whose TOF is the flight to each
// receiver that is in range, taking the robot's motion during the flight into account, plus
// Gaussian range noise. Ground truth comes with every odometry sample.
#include <cstdint>
#include <queue>
#include <random>
#include <vector>

#include "beaconloc/core/measurements.hpp"
#include "scenario.hpp"

namespace beaconloc::sim {

struct SimEvent {
  enum class Kind { kOdometry, kTof };
  Kind kind = Kind::kOdometry;
  StampNs stamp_ns = 0;                  // sim time: odometry stamp, or arrival of the pulse
  OdometrySample odometry;               // kOdometry
  Pose2 truth_map_base = Pose2::Zero();  // kOdometry: true pose at stamp_ns
  RawTofSample tof;                      // kTof
};

class SimSource {
 public:
  SimSource(Scenario scenario, std::uint64_t seed);
  // Appends, in stamp order, every event with stamp_ns <= until_ns (sim time from 0).
  void advance(StampNs until_ns, std::vector<SimEvent>& out);
  const Scenario& scenario() const { return scenario_; }

 private:
  void fire(StampNs fire_ns);
  SimEvent odometry_at(StampNs stamp_ns);

  struct Later {
    bool operator()(const SimEvent& a, const SimEvent& b) const {
      return a.stamp_ns != b.stamp_ns ? a.stamp_ns > b.stamp_ns
                                      : a.tof.sequence_number > b.tof.sequence_number;
    }
  };
  Scenario scenario_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> unit_normal_{0.0, 1.0};
  StampNs next_odometry_ns_;
  StampNs next_fire_ns_;
  std::uint64_t slot_ = 0;
  std::uint64_t tof_sequence_ = 0;
  std::priority_queue<SimEvent, std::vector<SimEvent>, Later> pending_tofs_;
};

// Arrival time of a pulse fired at fire_s from `beacon` at the receiver mounted at
// receiver_base_m on a robot moving along `trajectory` (seed 002 eq. 20: the receiver keeps
// moving while the pulse is in flight). Fixed-point iteration; converges since v << c.
double pulse_arrival_s(const Trajectory& trajectory, const Eigen::Vector2d& receiver_base_m,
                       double receiver_z_m, const Eigen::Vector3d& beacon_map_m, double fire_s,
                       double speed_of_sound_mps);

}  // namespace beaconloc::sim
