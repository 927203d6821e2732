// The beaconloc serial protocol v1 (docs/serial-protocol.md) through FrameParser: the document's
// examples byte for byte, every type's round trip through the encoders, the refusals a checksum
// cannot catch, sequence gaps, arrival stamps and a frame cut off by the line going away.
#include "frame_parser.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "frame_encoder.hpp"

namespace beaconloc::serial {
namespace {

std::vector<std::uint8_t> hex(const std::string& text) {
  std::vector<std::uint8_t> bytes;
  std::istringstream in(text);
  std::string byte;
  while (in >> byte) bytes.push_back(static_cast<std::uint8_t>(std::stoul(byte, nullptr, 16)));
  return bytes;
}

std::vector<Frame> parse(FrameParser& parser, const std::vector<std::uint8_t>& bytes,
                         StampNs arrival_ns = 0) {
  std::vector<Frame> out;
  parser.push(bytes.data(), bytes.size(), arrival_ns, out);
  return out;
}

std::uint64_t rejected(const FrameParser& parser, FrameRejection reason) {
  return parser.counts().rejections(reason);
}

// docs/serial-protocol.md, "Examples": the same bytes, the same values.
TEST(SerialFrameParser, DecodesTheDocumentsExamples) {
  FrameParser parser(Protocol::kBeaconloc);
  const auto frames =
      parse(parser, hex("B7 4C 01 01 2A 10 87 D6 12 00 80 96 98 00 05 01 02 01 66 08 00 00 C8 FA"
                        " B7 4C 01 02 2B 10 D0 12 13 00 90 D0 03 00 B8 17 FE FF 30 57 05 00 B5 E6"
                        " B7 4C 01 03 2C 04 20 D6 13 00 D8 AF"));
  ASSERT_EQ(frames.size(), 3u);
  const auto& tof = std::get<TofFrame>(frames[0].body);
  EXPECT_EQ(frames[0].sequence, 0x2A);
  EXPECT_EQ(tof.fire_time_us, 1234567u);
  EXPECT_EQ(tof.tof_ns, 10000000u);
  EXPECT_EQ(tof.beacon_id, 261);
  EXPECT_EQ(tof.receiver_id, 2);
  EXPECT_TRUE(tof.has_temperature);
  EXPECT_DOUBLE_EQ(tof.temperature_c, 21.5);
  const auto& odometry = std::get<OdometryFrame>(frames[1].body);
  EXPECT_EQ(frames[1].sequence, 0x2B);
  EXPECT_EQ(odometry.stamp_us, 1250000u);
  EXPECT_DOUBLE_EQ(odometry.right_mps, 0.25);
  EXPECT_DOUBLE_EQ(odometry.left_mps, -0.125);
  EXPECT_DOUBLE_EQ(odometry.wheel_base_m, 0.35);
  EXPECT_EQ(std::get<HeartbeatFrame>(frames[2].body).stamp_us, 1300000u);
  EXPECT_EQ(frames[2].sequence, 0x2C);
  EXPECT_EQ(parser.counts().frames, 3u);
  EXPECT_EQ(parser.counts().garbage_bytes, 0u);
  EXPECT_EQ(parser.counts().frames_lost, 0u);
}

// The encoders write exactly the document's bytes too (the simulator speaks the documented wire).
TEST(SerialFrameParser, TheEncodersWriteTheDocumentsExamples) {
  TofFrame tof{1234567, 10000000, 261, 2, true, 21.5};
  EXPECT_EQ(encode(tof, 0x2A),
            hex("B7 4C 01 01 2A 10 87 D6 12 00 80 96 98 00 05 01 02 01 66 08 00 00 C8 FA"));
  OdometryFrame odometry{1250000, 0.25, -0.125, 0.35};
  EXPECT_EQ(encode(odometry, 0x2B),
            hex("B7 4C 01 02 2B 10 D0 12 13 00 90 D0 03 00 B8 17 FE FF 30 57 05 00 B5 E6"));
  EXPECT_EQ(encode(HeartbeatFrame{1300000}, 0x2C), hex("B7 4C 01 03 2C 04 20 D6 13 00 D8 AF"));
}

TEST(SerialFrameParser, EveryTypeRoundTripsThroughTheEncoders) {
  const TofFrame tofs[] = {{0, 0, 0, 0, false, 0.0},
                           {0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFF, 0xFF, true, -327.68},
                           {42, 29154, 7, 1, true, 327.67}};
  const OdometryFrame odometries[] = {{0, 0.0, 0.0, 0.0},
                                      {0xFFFFFFFFu, -2147483648 / 1e6, 2147483647 / 1e6, 4294967295 / 1e6},
                                      {1000, 1234567 / 1e6, -7654321 / 1e6, 412000 / 1e6}};
  FrameParser parser(Protocol::kBeaconloc);
  std::uint8_t sequence = 0;
  for (const TofFrame& tof : tofs) {
    const auto frames = parse(parser, encode(tof, sequence++));
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_TRUE(std::get<TofFrame>(frames[0].body) == tof);
  }
  for (const OdometryFrame& odometry : odometries) {
    const auto frames = parse(parser, encode(odometry, sequence++));
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_TRUE(std::get<OdometryFrame>(frames[0].body) == odometry);
  }
  const auto frames = parse(parser, encode(HeartbeatFrame{0xDEADBEEF}, sequence++));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(std::get<HeartbeatFrame>(frames[0].body).stamp_us, 0xDEADBEEFu);
  EXPECT_EQ(parser.counts().frames, 7u);
  EXPECT_EQ(parser.counts().frames_lost, 0u);
}

// Nothing clamped: a value its field cannot carry is the simulator's error, thrown.
TEST(SerialFrameParser, TheEncodersRefuseValuesTheWireCannotCarry) {
  EXPECT_THROW(encode(TofFrame{0, 0, 0, 0, true, 400.0}, 0), std::invalid_argument);
  EXPECT_THROW(encode(TofFrame{0, 0, 0, 0, true, std::nan("")}, 0), std::invalid_argument);
  EXPECT_THROW(encode(OdometryFrame{0, 2200.0, 0.0, 0.3}, 0), std::invalid_argument);
  EXPECT_THROW(encode(OdometryFrame{0, 0.0, 0.0, -0.3}, 0), std::invalid_argument);
  EXPECT_THROW(encode_beaconloc_raw(1, 1, 0, std::vector<std::uint8_t>(256)), std::invalid_argument);
}

// Refused on the header alone, each with its own reason, without waiting for the bytes the
// length announces: a length of 255 that never comes holds nothing up.
TEST(SerialFrameParser, AHeaderItCannotTakeIsRefusedAtOnceWithItsOwnReason) {
  struct Case {
    std::vector<std::uint8_t> header;
    FrameRejection reason;
  };
  const Case cases[] = {
      {{0xB7, 0x4C, 0x01, 0x01, 0x00, 0xFF}, FrameRejection::kBadLength},       // a TOF of 255 bytes
      {{0xB7, 0x4C, 0x01, 0x03, 0x00, 0x10}, FrameRejection::kBadLength},       // a heartbeat of 16
      {{0xB7, 0x4C, 0x01, 0x04, 0x00, 0x04}, FrameRejection::kUnknownType},     // type 4
      {{0xB7, 0x4C, 0x01, 0x00, 0x00, 0x04}, FrameRejection::kUnknownType},     // type 0
      {{0xB7, 0x4C, 0x02, 0x01, 0x00, 0x10}, FrameRejection::kUnknownVersion},  // version 2
      {{0xB7, 0x4C, 0x00, 0x01, 0x00, 0x10}, FrameRejection::kUnknownVersion},  // version 0
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(to_string(c.reason));
    FrameParser parser(Protocol::kBeaconloc);
    EXPECT_TRUE(parse(parser, c.header).empty());
    EXPECT_EQ(rejected(parser, c.reason), 1u);
    EXPECT_EQ(parser.pending_bytes(), 0u);                      // nothing held for the announced bytes
    EXPECT_EQ(rejected(parser, FrameRejection::kGarbage), 0u);  // the header's tail is that refusal's
    EXPECT_EQ(parser.counts().garbage_bytes, c.header.size());
    // The next frame right behind it is found in the same read.
    auto bytes = c.header;
    const auto next = encode(HeartbeatFrame{5}, 9);
    bytes.insert(bytes.end(), next.begin(), next.end());
    FrameParser again(Protocol::kBeaconloc);
    EXPECT_EQ(parse(again, bytes).size(), 1u);
  }
}

// A frame whose checksum holds but whose reserved flag bits or reserved bytes are not zero:
// refused as such, whole (no garbage), its sequence number taken as sent.
TEST(SerialFrameParser, ReservedBitsOrBytesSetAreRefusedOnAFrameWhoseChecksumHolds) {
  std::vector<std::uint8_t> payload = {1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 4, 0x02, 0, 0, 0, 0};  // flag bit 1
  FrameParser parser(Protocol::kBeaconloc);
  EXPECT_TRUE(parse(parser, encode_beaconloc_raw(1, 0x01, 10, payload)).empty());
  payload[11] = 0x81;  // bit 0 valid, bit 7 reserved
  EXPECT_TRUE(parse(parser, encode_beaconloc_raw(1, 0x01, 11, payload)).empty());
  payload[11] = 0x01;
  payload[15] = 0x01;  // the reserved u16
  EXPECT_TRUE(parse(parser, encode_beaconloc_raw(1, 0x01, 12, payload)).empty());
  payload[15] = 0x00;
  EXPECT_EQ(parse(parser, encode_beaconloc_raw(1, 0x01, 13, payload)).size(), 1u);
  EXPECT_EQ(rejected(parser, FrameRejection::kReservedBitsSet), 3u);
  EXPECT_EQ(parser.counts().garbage_bytes, 0u);
  EXPECT_EQ(parser.counts().frames_lost, 0u);
  EXPECT_EQ(parser.counts().frames, 1u);
}

// Temperature flag clear: the field is no temperature (senders write 0); the frame says so.
TEST(SerialFrameParser, ATofWithoutTheTemperatureFlagHasNoTemperature) {
  std::vector<std::uint8_t> payload = {1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 4, 0x00, 0x66, 0x08, 0, 0};
  FrameParser parser(Protocol::kBeaconloc);
  const auto frames = parse(parser, encode_beaconloc_raw(1, 0x01, 0, payload));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_FALSE(std::get<TofFrame>(frames[0].body).has_temperature);
  EXPECT_EQ(std::get<TofFrame>(frames[0].body).temperature_c, 0.0);
}

// A jump in the sequence counts the frames skipped, modulo 256; the frame itself is taken.
TEST(SerialFrameParser, SequenceGapsAreCountedAsFramesLostAcrossTheWrap) {
  FrameParser parser(Protocol::kBeaconloc);
  std::vector<std::uint8_t> bytes;
  for (int sequence : {254, 255, 0, 3, 4, 250}) {
    const auto frame =
        encode(HeartbeatFrame{static_cast<std::uint32_t>(sequence)}, static_cast<std::uint8_t>(sequence));
    bytes.insert(bytes.end(), frame.begin(), frame.end());
  }
  EXPECT_EQ(parse(parser, bytes).size(), 6u);
  EXPECT_EQ(parser.counts().frames_lost, 2u + 245u);  // 1 and 2; 5 to 249
}

// A frame sent twice (its sequence number that of the frame before it) is taken once: counted a
// duplicate, not 255 frames lost.
TEST(SerialFrameParser, AFrameSentTwiceIsTakenOnceAndCountedDuplicate) {
  FrameParser parser(Protocol::kBeaconloc);
  std::vector<std::uint8_t> bytes;
  for (int sequence : {7, 8, 8, 9}) {
    const auto frame =
        encode(HeartbeatFrame{static_cast<std::uint32_t>(sequence)}, static_cast<std::uint8_t>(sequence));
    bytes.insert(bytes.end(), frame.begin(), frame.end());
  }
  EXPECT_EQ(parse(parser, bytes).size(), 3u);
  EXPECT_EQ(parser.counts().rejections(FrameRejection::kDuplicate), 1u);
  EXPECT_EQ(parser.counts().frames_lost, 0u);
}

// A frame's arrival is the host time of the read that completed it.
TEST(SerialFrameParser, ArrivalIsTheReadThatCompletedTheFrame) {
  FrameParser parser(Protocol::kBeaconloc);
  const auto first = encode(HeartbeatFrame{1}, 0);
  const auto second = encode(HeartbeatFrame{2}, 1);
  std::vector<Frame> out;
  parser.push(first.data(), 5, 100, out);
  EXPECT_TRUE(out.empty());
  std::vector<std::uint8_t> rest(first.begin() + 5, first.end());
  rest.insert(rest.end(), second.begin(), second.begin() + 3);
  parser.push(rest.data(), rest.size(), 200, out);
  parser.push(second.data() + 3, second.size() - 3, 300, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].arrival_ns, 200);
  EXPECT_EQ(out[1].arrival_ns, 300);
}

// The line went away mid-frame: on reopen the partial frame is dropped and counted truncated,
// and the first frame of the new session sets the sequence afresh (no frames counted lost).
TEST(SerialFrameParser, APartialFrameIsCountedTruncatedWhenTheLineIsReopened) {
  FrameParser parser(Protocol::kBeaconloc);
  parse(parser, encode(HeartbeatFrame{1}, 7));
  const auto cut = encode(TofFrame{1, 2, 3, 4, false, 0.0}, 8);
  EXPECT_TRUE(parse(parser, std::vector<std::uint8_t>(cut.begin(), cut.begin() + 15)).empty());
  EXPECT_EQ(parser.pending_bytes(), 15u);
  parser.reset_partial();
  EXPECT_EQ(parser.pending_bytes(), 0u);
  EXPECT_EQ(rejected(parser, FrameRejection::kTruncated), 1u);
  EXPECT_EQ(parser.counts().garbage_bytes, 15u);
  EXPECT_EQ(parse(parser, encode(HeartbeatFrame{1}, 200)).size(), 1u);
  EXPECT_EQ(parser.counts().frames_lost, 0u);
  parser.reset_partial();  // nothing pending: nothing counted
  EXPECT_EQ(rejected(parser, FrameRejection::kTruncated), 1u);
}

}  // namespace
}  // namespace beaconloc::serial
