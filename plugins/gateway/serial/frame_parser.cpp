#include "frame_parser.hpp"

#include <algorithm>
#include <cstring>

#include "crc16.hpp"

namespace beaconloc::serial {

FrameParser::FrameParser(Protocol protocol)
    : protocol_(protocol),
      header_bytes_(protocol == Protocol::kBeaconloc ? wire::kBeaconlocHeaderBytes
                                                     : wire::kMarvelmindHeaderBytes),
      capacity_(max_frame_bytes(protocol)) {}

void FrameParser::push(const std::uint8_t* data, std::size_t size, StampNs arrival_ns,
                       std::vector<Frame>& out) {
  counts_.bytes += size;
  // In slices that fit the buffer: a scan always leaves it less than full (a full buffer holds a
  // complete frame, which is taken or refused), so every slice finds room.
  while (size > 0) {
    const std::size_t n = std::min(size, capacity_ - pending_);
    std::memcpy(buffer_.data() + pending_, data, n);
    pending_ += n;
    data += n;
    size -= n;
    scan(arrival_ns, out);
  }
}

void FrameParser::reset_partial() {
  if (pending_ > 0) {
    counts_.garbage_bytes += pending_;
    ++counts_.rejected[static_cast<std::size_t>(FrameRejection::kTruncated)];
  }
  pending_ = 0;
  skipping_ = false;
  have_sequence_ = false;
}

bool FrameParser::is_second_sync_byte(std::uint8_t byte) const {
  if (protocol_ == Protocol::kBeaconloc) return byte == wire::kBeaconlocSync1;
  return byte == wire::kMarvelmindStreaming || byte == wire::kMarvelmindReadWrite;
}

void FrameParser::skip_garbage(std::size_t bytes) {
  counts_.garbage_bytes += bytes;
  if (!skipping_) ++counts_.rejected[static_cast<std::size_t>(FrameRejection::kGarbage)];
  skipping_ = true;
}

void FrameParser::refuse(FrameRejection reason) {
  ++counts_.rejected[static_cast<std::size_t>(reason)];
  counts_.garbage_bytes += 1;  // its first sync byte; the rest is scanned again
  skipping_ = true;            // the bytes skipped after it are this refusal's, not a new garbage run
}

FrameParser::HeaderVerdict FrameParser::judge_header(const std::uint8_t* frame) const {
  HeaderVerdict verdict;
  if (protocol_ == Protocol::kBeaconloc) {
    const std::uint8_t version = frame[2];
    const std::uint8_t type = frame[3];
    const std::uint8_t length = frame[5];
    std::uint8_t expected = 0;
    if (version != wire::kBeaconlocVersion) {
      verdict.refused = true;
      verdict.reason = FrameRejection::kUnknownVersion;
      return verdict;
    }
    switch (type) {
      case wire::kTypeTof:
        expected = wire::kTofPayloadBytes;
        break;
      case wire::kTypeOdometry:
        expected = wire::kOdometryPayloadBytes;
        break;
      case wire::kTypeHeartbeat:
        expected = wire::kHeartbeatPayloadBytes;
        break;
      default:
        verdict.refused = true;
        verdict.reason = FrameRejection::kUnknownType;
        return verdict;
    }
    if (length != expected) {
      verdict.refused = true;
      verdict.reason = FrameRejection::kBadLength;
      return verdict;
    }
    verdict.frame_bytes = wire::kBeaconlocHeaderBytes + length + wire::kChecksumBytes;
    return verdict;
  }
  // Marvelmind: only the code we read has a length we know; any other code of any length is
  // waited for (at most 262 bytes) and counted unused if its checksum holds.
  const std::uint16_t code = wire::get_u16(frame + 2);
  const std::uint8_t size = frame[4];
  if (frame[1] == wire::kMarvelmindStreaming && code == wire::kMarvelmindDistancesCode &&
      size != wire::kMarvelmindDistancesPayloadBytes) {
    verdict.refused = true;
    verdict.reason = FrameRejection::kBadLength;
    return verdict;
  }
  verdict.frame_bytes = wire::kMarvelmindHeaderBytes + size + wire::kChecksumBytes;
  return verdict;
}

bool FrameParser::checksum_ok(const std::uint8_t* frame, std::size_t frame_bytes) const {
  if (protocol_ == Protocol::kMarvelmind) return crc16_modbus(frame, frame_bytes) == 0;
  const std::size_t covered = frame_bytes - 2 - wire::kChecksumBytes;  // version..payload
  return crc16_ccitt_false(frame + 2, covered) == wire::get_u16(frame + frame_bytes - wire::kChecksumBytes);
}

void FrameParser::scan(StampNs arrival_ns, std::vector<Frame>& out) {
  const std::uint8_t sync0 =
      protocol_ == Protocol::kBeaconloc ? wire::kBeaconlocSync0 : wire::kMarvelmindAddress;
  std::size_t at = 0;
  const std::uint8_t* const end = buffer_.data() + pending_;
  while (at < pending_) {
    const std::uint8_t* p = buffer_.data() + at;
    const std::size_t available = pending_ - at;
    if (p[0] != sync0) {
      const std::uint8_t* next = std::find(p, end, sync0);
      const auto skipped = static_cast<std::size_t>(next - p);
      skip_garbage(skipped);
      at += skipped;
      continue;
    }
    if (available < 2) break;
    if (!is_second_sync_byte(p[1])) {
      skip_garbage(1);
      at += 1;
      continue;
    }
    if (available < header_bytes_) break;
    const HeaderVerdict verdict = judge_header(p);
    if (verdict.refused) {
      refuse(verdict.reason);
      at += 1;
      continue;
    }
    if (available < verdict.frame_bytes) break;
    if (!checksum_ok(p, verdict.frame_bytes)) {
      refuse(FrameRejection::kBadChecksum);
      at += 1;
      continue;
    }
    if (protocol_ == Protocol::kBeaconloc) {
      accept_beaconloc(p, arrival_ns, out);
    } else {
      accept_marvelmind(p, arrival_ns, out);
    }
    skipping_ = false;
    at += verdict.frame_bytes;
  }
  std::memmove(buffer_.data(), buffer_.data() + at, pending_ - at);
  pending_ -= at;
}

void FrameParser::accept_beaconloc(const std::uint8_t* frame, StampNs arrival_ns, std::vector<Frame>& out) {
  // The checksum vouches for the sequence number, refused frame or not: it was sent, not lost.
  const std::uint8_t sequence = frame[4];
  if (have_sequence_ && sequence == last_sequence_) {
    // The frame before it again (a module resending): taken once. (256 frames lost in a row would
    // read the same; the line's silence for them is told as a stall.)
    ++counts_.rejected[static_cast<std::size_t>(FrameRejection::kDuplicate)];
    return;
  }
  if (have_sequence_) counts_.frames_lost += static_cast<std::uint8_t>(sequence - last_sequence_ - 1);
  have_sequence_ = true;
  last_sequence_ = sequence;

  const std::uint8_t* payload = frame + wire::kBeaconlocHeaderBytes;
  Frame decoded;
  decoded.arrival_ns = arrival_ns;
  decoded.sequence = sequence;
  switch (frame[3]) {
    case wire::kTypeTof: {
      const std::uint8_t flags = payload[11];
      if ((flags & ~wire::kTofFlagTemperatureValid) != 0 || wire::get_u16(payload + 14) != 0) {
        ++counts_.rejected[static_cast<std::size_t>(FrameRejection::kReservedBitsSet)];
        return;
      }
      TofFrame tof;
      tof.fire_time_us = wire::get_u32(payload);
      tof.tof_ns = wire::get_u32(payload + 4);
      tof.beacon_id = wire::get_u16(payload + 8);
      tof.receiver_id = payload[10];
      tof.has_temperature = (flags & wire::kTofFlagTemperatureValid) != 0;
      tof.temperature_c = tof.has_temperature ? wire::get_i16(payload + 12) / 100.0 : 0.0;
      decoded.body = tof;
      break;
    }
    case wire::kTypeOdometry: {
      OdometryFrame odometry;
      odometry.stamp_us = wire::get_u32(payload);
      odometry.right_mps = wire::get_i32(payload + 4) / 1e6;
      odometry.left_mps = wire::get_i32(payload + 8) / 1e6;
      odometry.wheel_base_m = wire::get_u32(payload + 12) / 1e6;
      decoded.body = odometry;
      break;
    }
    default: {  // kTypeHeartbeat: judge_header let no other type through
      decoded.body = HeartbeatFrame{wire::get_u32(payload)};
      break;
    }
  }
  ++counts_.frames;
  out.push_back(std::move(decoded));
}

void FrameParser::accept_marvelmind(const std::uint8_t* frame, StampNs arrival_ns, std::vector<Frame>& out) {
  if (frame[1] != wire::kMarvelmindStreaming || wire::get_u16(frame + 2) != wire::kMarvelmindDistancesCode) {
    ++counts_.unused_frames;
    return;
  }
  const std::uint8_t* payload = frame + wire::kMarvelmindHeaderBytes;
  DistancesFrame distances;
  distances.hedge_address = payload[0];
  for (std::size_t i = 0; i < wire::kMarvelmindDistanceSlots; ++i) {
    const std::uint8_t* slot = payload + 1 + i * wire::kMarvelmindSlotBytes;
    if (slot[0] == 0) continue;  // an empty slot (docs/serial-protocol.md: our reading of address 0)
    distances.slots.push_back({slot[0], wire::get_u32(slot + 1)});
  }
  distances.stamp_ms = wire::get_u32(payload + wire::kMarvelmindDistancesStampOffset);
  Frame decoded;
  decoded.body = std::move(distances);
  decoded.arrival_ns = arrival_ns;
  ++counts_.frames;
  out.push_back(std::move(decoded));
}

}  // namespace beaconloc::serial
