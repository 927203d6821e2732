#include "frame_encoder.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "crc16.hpp"
#include "wire_format.hpp"

namespace beaconloc::serial {
namespace {

void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}
void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<std::uint8_t>((v >> shift) & 0xFF));
}

// value * scale rounded to the nearest integer in [lo, hi], or an error naming the field.
std::int64_t scaled(double value, double scale, std::int64_t lo, std::int64_t hi, const char* field) {
  const double x = value * scale;
  if (!std::isfinite(x) || x < static_cast<double>(lo) - 0.5 || x > static_cast<double>(hi) + 0.5) {
    throw std::invalid_argument(std::string("serial frame: ") + field + " = " + std::to_string(value) +
                                " does not fit its wire field");
  }
  const std::int64_t n = std::llround(x);
  if (n < lo || n > hi) {
    throw std::invalid_argument(std::string("serial frame: ") + field + " does not fit its wire field");
  }
  return n;
}

void check_payload_size(std::size_t size) {
  if (size > 255) throw std::invalid_argument("serial frame: a payload of more than 255 bytes");
}

}  // namespace

std::vector<std::uint8_t> encode_beaconloc_raw(std::uint8_t version, std::uint8_t type, std::uint8_t sequence,
                                               const std::vector<std::uint8_t>& payload) {
  check_payload_size(payload.size());
  // Reserved, then appended: GCC 12's -Warray-bounds misreads an insert into a vector built from a
  // braced list (a false positive at -O3).
  std::vector<std::uint8_t> out;
  out.reserve(wire::kBeaconlocHeaderBytes + payload.size() + wire::kChecksumBytes);
  for (std::uint8_t b : {wire::kBeaconlocSync0, wire::kBeaconlocSync1, version, type, sequence})
    out.push_back(b);
  out.push_back(static_cast<std::uint8_t>(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  put_u16(out, crc16_ccitt_false(out.data() + 2, out.size() - 2));  // version..payload
  return out;
}

std::vector<std::uint8_t> encode_marvelmind_raw(std::uint8_t packet_type, std::uint16_t code,
                                                const std::vector<std::uint8_t>& payload) {
  check_payload_size(payload.size());
  std::vector<std::uint8_t> out;
  out.reserve(wire::kMarvelmindHeaderBytes + payload.size() + wire::kChecksumBytes);
  out.push_back(wire::kMarvelmindAddress);
  out.push_back(packet_type);
  put_u16(out, code);
  out.push_back(static_cast<std::uint8_t>(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  put_u16(out, crc16_modbus(out.data(), out.size()));
  return out;
}

std::vector<std::uint8_t> encode(const TofFrame& frame, std::uint8_t sequence) {
  std::vector<std::uint8_t> payload;
  put_u32(payload, frame.fire_time_us);
  put_u32(payload, frame.tof_ns);
  put_u16(payload, frame.beacon_id);
  payload.push_back(frame.receiver_id);
  payload.push_back(frame.has_temperature ? wire::kTofFlagTemperatureValid : 0);
  const std::int64_t centi_c =
      frame.has_temperature ? scaled(frame.temperature_c, 100.0, std::numeric_limits<std::int16_t>::min(),
                                     std::numeric_limits<std::int16_t>::max(), "temperature_c")
                            : 0;
  put_u16(payload, static_cast<std::uint16_t>(centi_c & 0xFFFF));
  put_u16(payload, 0);  // reserved
  return encode_beaconloc_raw(wire::kBeaconlocVersion, wire::kTypeTof, sequence, payload);
}

std::vector<std::uint8_t> encode(const OdometryFrame& frame, std::uint8_t sequence) {
  constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
  constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();
  std::vector<std::uint8_t> payload;
  put_u32(payload, frame.stamp_us);
  const std::int64_t right = scaled(frame.right_mps, 1e6, kI32Min, kI32Max, "right_mps");
  const std::int64_t left = scaled(frame.left_mps, 1e6, kI32Min, kI32Max, "left_mps");
  const std::int64_t base =
      scaled(frame.wheel_base_m, 1e6, 0, std::numeric_limits<std::uint32_t>::max(), "wheel_base_m");
  put_u32(payload, static_cast<std::uint32_t>(right & 0xFFFFFFFF));
  put_u32(payload, static_cast<std::uint32_t>(left & 0xFFFFFFFF));
  put_u32(payload, static_cast<std::uint32_t>(base));
  return encode_beaconloc_raw(wire::kBeaconlocVersion, wire::kTypeOdometry, sequence, payload);
}

std::vector<std::uint8_t> encode(const HeartbeatFrame& frame, std::uint8_t sequence) {
  std::vector<std::uint8_t> payload;
  put_u32(payload, frame.stamp_us);
  return encode_beaconloc_raw(wire::kBeaconlocVersion, wire::kTypeHeartbeat, sequence, payload);
}

std::vector<std::uint8_t> encode_marvelmind_distances(const DistancesFrame& frame) {
  if (frame.slots.size() > wire::kMarvelmindDistanceSlots) {
    throw std::invalid_argument("marvelmind distances: more than 4 slots");
  }
  std::vector<std::uint8_t> payload;
  payload.reserve(wire::kMarvelmindDistancesPayloadBytes);
  payload.push_back(frame.hedge_address);
  for (std::size_t i = 0; i < wire::kMarvelmindDistanceSlots; ++i) {
    if (i < frame.slots.size()) {
      if (frame.slots[i].beacon_address == 0) {
        throw std::invalid_argument("marvelmind distances: beacon address 0 marks an empty slot");
      }
      payload.push_back(frame.slots[i].beacon_address);
      put_u32(payload, frame.slots[i].distance_mm);
    } else {
      payload.push_back(0);
      put_u32(payload, 0);
    }
    payload.push_back(0);  // reserved
  }
  put_u32(payload, frame.stamp_ms);
  for (int i = 0; i < 3; ++i) payload.push_back(0);  // reserved (marvelmind.c reads a u16 "timeShift" there)
  return encode_marvelmind_raw(wire::kMarvelmindStreaming, wire::kMarvelmindDistancesCode, payload);
}

}  // namespace beaconloc::serial
