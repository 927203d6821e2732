#pragma once
// What a beacon-gateway publishes, from whichever source: the simulator, a replayed recording
// (or, later, the hardware). DDS-free.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/pose2.hpp"
#include "beaconloc/core/receiver_array.hpp"
#include "beaconloc/core/rejection_counter.hpp"

namespace beaconloc {

struct SourceEvent {
  enum class Kind { kOdometry, kTof, kPulse, kLaserScan, kTruth };
  Kind kind = Kind::kOdometry;
  StampNs stamp_ns = 0;  // odometry stamp, arrival of a pulse (kTof, kPulse), scan or truth time

  OdometrySample odometry;                             // kOdometry
  RawTofSample tof;                                    // kTof
  PulseArrivalSample pulse;                            // kPulse
  std::uint32_t true_beacon_id = kBeaconUnidentified;  // kTof, kPulse: who fired, for evaluation only
  bool tof_is_echo = false;                            // kTof, kPulse: simulated echo, for evaluation only
  LaserScanSample scan;                                // kLaserScan

  // Ground truth at stamp_ns: on kTruth events, and on the simulator's kOdometry events.
  bool has_truth = false;
  Pose2 truth_map_base = Pose2::Zero();
  bool truth_has_yaw = true;
};

class Source {
 public:
  virtual ~Source() = default;
  // Appends, in stamp order, every event with stamp_ns <= until_ns.
  virtual void advance(StampNs until_ns, std::vector<SourceEvent>& out) = 0;
  // No event will come after the ones already given (the end of a recording).
  virtual bool exhausted() const = 0;
  // A recording ends; a simulation runs for as long as it is asked to.
  virtual bool finite() const = 0;
  virtual BeaconMap beacon_map() const = 0;
  virtual ReceiverArray receivers() const = 0;
  // Stamp of the first event; simulated time starts at 0.
  virtual StampNs first_stamp_ns() const = 0;
  // Last stamp of a recording; the scenario's default duration for a simulation.
  virtual StampNs last_stamp_ns() const = 0;
  // True when stamps are relative (simulated time from 0): the gateway offsets them to the wall
  // clock. A recording keeps its own clock.
  virtual bool relative_stamps() const = 0;
  virtual std::string describe() const = 0;
  // How its beacons are heard: times of flight (kTof events, RawTof) or, from beacons without a
  // radio message, pulse arrivals (kPulse events, PulseArrival). Never decoded ranges.
  virtual BeaconInput beacon_input() const { return BeaconInput::kRawTof; }
  // Input the source refused while reading it (a recording's malformed rows), by reason.
  virtual RejectionCounter input_rejections() const { return {}; }

  // Selective activation (seed 004 Sec. 3): whether the source fires the beacons a plan names
  // (the simulator, hardware that calls its beacons), and the firing slot it judges a plan's age
  // by. A recording fired what it fired: it honours none.
  virtual bool honours_firing_plan() const { return false; }
  virtual StampNs slot_period_ns() const { return 0; }
  // The beacons to fire from the next slot on; nullopt: every beacon in turn.
  virtual void set_firing_plan(std::optional<std::vector<std::uint32_t>> /*beacon_ids*/) {}
  // The firings since last asked (for a firing log), and whether each followed a plan.
  struct Firing {
    StampNs fire_stamp_ns = 0;
    std::uint32_t beacon_id = 0;
    bool planned = false;  // chosen by a plan, not by the firing order
    bool heard = false;    // some receiver heard it
  };
  virtual std::vector<Firing> take_firings() { return {}; }
};

}  // namespace beaconloc
