#pragma once
// Frames as a sender writes them: for the simulator that plays a receiver module into a
// pseudo-terminal, and for tests. A value the wire cannot carry (a NaN, a speed beyond the i32
// field, a temperature beyond the i16 field) throws std::invalid_argument: nothing is clamped.
#include <cstdint>
#include <vector>

#include "frames.hpp"

namespace beaconloc::serial {

// beaconloc serial protocol v1.
std::vector<std::uint8_t> encode(const TofFrame& frame, std::uint8_t sequence);
std::vector<std::uint8_t> encode(const OdometryFrame& frame, std::uint8_t sequence);
std::vector<std::uint8_t> encode(const HeartbeatFrame& frame, std::uint8_t sequence);

// Marvelmind raw distances (code 0x0004): at most four slots, none with beacon address 0 (the
// empty slot's mark); the slots left over are sent empty.
std::vector<std::uint8_t> encode_marvelmind_distances(const DistancesFrame& frame);

// Any frame of either protocol from its raw parts, checksum computed: frames the parser refuses
// or does not use, for tests. The length field is payload.size() (at most 255).
std::vector<std::uint8_t> encode_beaconloc_raw(std::uint8_t version, std::uint8_t type, std::uint8_t sequence,
                                               const std::vector<std::uint8_t>& payload);
std::vector<std::uint8_t> encode_marvelmind_raw(std::uint8_t packet_type, std::uint16_t code,
                                                const std::vector<std::uint8_t>& payload);

}  // namespace beaconloc::serial
