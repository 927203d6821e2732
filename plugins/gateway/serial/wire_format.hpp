#pragma once
// The two protocols' byte layouts (docs/serial-protocol.md), shared by the parser and the
// encoders so that the two cannot disagree. Every multi-byte field is little-endian.
#include <cstddef>
#include <cstdint>

namespace beaconloc::serial::wire {

// beaconloc serial protocol v1: B7 4C version type sequence length payload crc16(lo, hi); the
// CRC-16/CCITT-FALSE covers version..payload.
inline constexpr std::uint8_t kBeaconlocSync0 = 0xB7;
inline constexpr std::uint8_t kBeaconlocSync1 = 0x4C;
inline constexpr std::uint8_t kBeaconlocVersion = 1;
inline constexpr std::size_t kBeaconlocHeaderBytes = 6;  // sync (2), version, type, sequence, length
inline constexpr std::uint8_t kTypeTof = 0x01;
inline constexpr std::uint8_t kTypeOdometry = 0x02;
inline constexpr std::uint8_t kTypeHeartbeat = 0x03;
inline constexpr std::uint8_t kTofPayloadBytes = 16;
inline constexpr std::uint8_t kOdometryPayloadBytes = 16;
inline constexpr std::uint8_t kHeartbeatPayloadBytes = 4;
inline constexpr std::uint8_t kTofFlagTemperatureValid = 0x01;
inline constexpr std::size_t kBeaconlocMaxFrameBytes = kBeaconlocHeaderBytes + 16 + 2;

// Marvelmind: FF type code(lo, hi) size payload crc16(lo, hi); the CRC-16/MODBUS covers
// everything before it.
inline constexpr std::uint8_t kMarvelmindAddress = 0xFF;    // the destination address: every device
inline constexpr std::uint8_t kMarvelmindStreaming = 0x47;  // packet type: streaming
inline constexpr std::uint8_t kMarvelmindReadWrite = 0x4A;  // packet type: read/write (waypoints)
inline constexpr std::size_t kMarvelmindHeaderBytes = 5;
inline constexpr std::uint16_t kMarvelmindDistancesCode = 0x0004;
inline constexpr std::uint8_t kMarvelmindDistancesPayloadBytes = 32;
inline constexpr std::size_t kMarvelmindDistanceSlots = 4;
inline constexpr std::size_t kMarvelmindSlotBytes = 6;              // address, distance u32, reserved
inline constexpr std::size_t kMarvelmindDistancesStampOffset = 25;  // in the payload
inline constexpr std::size_t kMarvelmindMaxFrameBytes = kMarvelmindHeaderBytes + 255 + 2;

inline constexpr std::size_t kChecksumBytes = 2;

inline std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (static_cast<std::uint16_t>(p[1]) << 8));
}
inline std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
// Two's complement, as the wire sends it (no implementation-defined conversions).
inline std::int16_t get_i16(const std::uint8_t* p) {
  const std::uint16_t u = get_u16(p);
  return u < 0x8000u ? static_cast<std::int16_t>(u)
                     : static_cast<std::int16_t>(static_cast<int>(u) - 0x10000);
}
inline std::int32_t get_i32(const std::uint8_t* p) {
  const std::uint32_t u = get_u32(p);
  return u < 0x80000000u ? static_cast<std::int32_t>(u)
                         : static_cast<std::int32_t>(static_cast<std::int64_t>(u) - 0x100000000LL);
}

}  // namespace beaconloc::serial::wire
