#pragma once
// What a receiver module reports over the serial line, decoded (docs/serial-protocol.md). Stamps
// stay in the device's own clock here, as sent: DeviceClock (device_clock.hpp) maps them to the
// host's. Values are in SI units; each is exactly what its wire field holds (the wire's integer
// divided by its scale), nothing rounded or repaired.
#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include "beaconloc/core/time.hpp"

namespace beaconloc::serial {

enum class Protocol : std::uint8_t {
  kBeaconloc,   // beaconloc serial protocol v1 (ours)
  kMarvelmind,  // Marvelmind Indoor Navigation System streaming packets (raw distances used)
};

// beaconloc type 0x01: one beacon's pulse heard by one receiver.
struct TofFrame {
  std::uint32_t fire_time_us = 0;  // device clock; wraps every 2^32 us
  std::uint32_t tof_ns = 0;
  std::uint16_t beacon_id = 0;
  std::uint8_t receiver_id = 0;
  bool has_temperature = false;
  double temperature_c = 0.0;  // centi-degrees / 100; 0 when has_temperature is false
};

// beaconloc type 0x02: the wheels' speeds.
struct OdometryFrame {
  std::uint32_t stamp_us = 0;  // device clock
  double right_mps = 0.0;      // um/s / 1e6
  double left_mps = 0.0;
  double wheel_base_m = 0.0;
};

// beaconloc type 0x03: the device is alive and its clock reads stamp_us.
struct HeartbeatFrame {
  std::uint32_t stamp_us = 0;  // device clock
};

// Marvelmind code 0x0004: a mobile beacon's distances to up to four stationary beacons.
struct DistancesFrame {
  struct Slot {
    std::uint8_t beacon_address = 0;
    std::uint32_t distance_mm = 0;
  };
  std::uint32_t stamp_ms = 0;  // device clock, milliseconds
  std::uint8_t hedge_address = 0;
  std::vector<Slot> slots;  // the filled slots only (beacon address != 0), in wire order
};

struct Frame {
  std::variant<TofFrame, OdometryFrame, HeartbeatFrame, DistancesFrame> body;
  StampNs arrival_ns = 0;                // the host time of the read that completed the frame
  std::optional<std::uint8_t> sequence;  // beaconloc frames; Marvelmind packets carry none
};

// Field by field, for tests and the simulator's round trips.
inline bool operator==(const TofFrame& a, const TofFrame& b) {
  return a.fire_time_us == b.fire_time_us && a.tof_ns == b.tof_ns && a.beacon_id == b.beacon_id &&
         a.receiver_id == b.receiver_id && a.has_temperature == b.has_temperature &&
         a.temperature_c == b.temperature_c;
}
inline bool operator==(const OdometryFrame& a, const OdometryFrame& b) {
  return a.stamp_us == b.stamp_us && a.right_mps == b.right_mps && a.left_mps == b.left_mps &&
         a.wheel_base_m == b.wheel_base_m;
}
inline bool operator==(const HeartbeatFrame& a, const HeartbeatFrame& b) { return a.stamp_us == b.stamp_us; }
inline bool operator==(const DistancesFrame::Slot& a, const DistancesFrame::Slot& b) {
  return a.beacon_address == b.beacon_address && a.distance_mm == b.distance_mm;
}
inline bool operator==(const DistancesFrame& a, const DistancesFrame& b) {
  return a.stamp_ms == b.stamp_ms && a.hedge_address == b.hedge_address && a.slots == b.slots;
}
inline bool operator==(const Frame& a, const Frame& b) {
  return a.body == b.body && a.arrival_ns == b.arrival_ns && a.sequence == b.sequence;
}
inline bool operator!=(const Frame& a, const Frame& b) { return !(a == b); }

}  // namespace beaconloc::serial
