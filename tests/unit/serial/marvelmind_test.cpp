// Marvelmind's streaming packets (docs/serial-protocol.md, "Marvelmind"): raw distances decoded
// as Marvelmind's own parsers read them, every other packet whose checksum holds counted unused
// and never garbage, a distances packet of the wrong size refused on its header.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "frame_encoder.hpp"
#include "frame_parser.hpp"

namespace beaconloc::serial {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes hex(const std::string& text) {
  Bytes bytes;
  std::istringstream in(text);
  std::string byte;
  while (in >> byte) bytes.push_back(static_cast<std::uint8_t>(std::stoul(byte, nullptr, 16)));
  return bytes;
}

std::vector<Frame> parse(FrameParser& parser, const Bytes& bytes) {
  std::vector<Frame> out;
  parser.push(bytes.data(), bytes.size(), 0, out);
  return out;
}

const char kDocumentsExample[] =
    "FF 47 04 00 20 05 01 29 09 00 00 00 02 80 0D 00 00 00 03 D7 11 00 00 00 00 00 00 00 00 00 40 E2 01 00 "
    "00 00 "
    "00 EE 2A";

// docs/serial-protocol.md's example: hedge 5; beacons 1, 2, 3 at 2.345, 3.456, 4.567 m; the
// fourth slot empty; 123456 ms.
TEST(SerialMarvelmind, DecodesTheDocumentsExample) {
  FrameParser parser(Protocol::kMarvelmind);
  const auto frames = parse(parser, hex(kDocumentsExample));
  ASSERT_EQ(frames.size(), 1u);
  const auto& distances = std::get<DistancesFrame>(frames[0].body);
  EXPECT_EQ(distances.hedge_address, 5);
  EXPECT_EQ(distances.stamp_ms, 123456u);
  ASSERT_EQ(distances.slots.size(), 3u);
  EXPECT_EQ(distances.slots[0].beacon_address, 1);
  EXPECT_EQ(distances.slots[0].distance_mm, 2345u);
  EXPECT_EQ(distances.slots[1].beacon_address, 2);
  EXPECT_EQ(distances.slots[1].distance_mm, 3456u);
  EXPECT_EQ(distances.slots[2].beacon_address, 3);
  EXPECT_EQ(distances.slots[2].distance_mm, 4567u);
  EXPECT_FALSE(frames[0].sequence.has_value());  // Marvelmind packets carry none
  EXPECT_EQ(parser.counts().frames_lost, 0u);
}

TEST(SerialMarvelmind, TheEncoderWritesTheDocumentsExample) {
  DistancesFrame distances;
  distances.hedge_address = 5;
  distances.stamp_ms = 123456;
  distances.slots = {{1, 2345}, {2, 3456}, {3, 4567}};
  EXPECT_EQ(encode_marvelmind_distances(distances), hex(kDocumentsExample));
}

// An empty slot (address 0) in the middle is left out; the slots after it are kept in order.
TEST(SerialMarvelmind, AnEmptySlotIsLeftOutWhereverItIs) {
  Bytes payload(32, 0);
  payload[0] = 7;                                              // hedge
  payload[1] = 11, payload[2] = 0x10, payload[3] = 0x27;       // beacon 11 at 10000 mm
  payload[7] = 0, payload[8] = 0x99;                           // slot 2 empty (its distance not read)
  payload[13] = 13, payload[14] = 0x01;                        // beacon 13 at 1 mm
  payload[19] = 0;                                             // slot 4 empty
  payload[25] = 0x01, payload[28] = 0x80;                      // stamp 0x80000001 ms
  payload[29] = 0xAB, payload[30] = 0xCD, payload[31] = 0xEF;  // the trailing bytes: not ours to judge
  FrameParser parser(Protocol::kMarvelmind);
  const auto frames = parse(parser, encode_marvelmind_raw(0x47, 0x0004, payload));
  ASSERT_EQ(frames.size(), 1u);
  const auto& distances = std::get<DistancesFrame>(frames[0].body);
  ASSERT_EQ(distances.slots.size(), 2u);
  EXPECT_EQ(distances.slots[0].beacon_address, 11);
  EXPECT_EQ(distances.slots[0].distance_mm, 10000u);
  EXPECT_EQ(distances.slots[1].beacon_address, 13);
  EXPECT_EQ(distances.slots[1].distance_mm, 1u);
  EXPECT_EQ(distances.stamp_ms, 0x80000001u);
}

TEST(SerialMarvelmind, DistancesRoundTripThroughTheEncoder) {
  DistancesFrame distances;
  distances.hedge_address = 0xFF;
  distances.stamp_ms = 0xFFFFFFFF;
  distances.slots = {{1, 0}, {255, 0xFFFFFFFF}, {3, 3}, {4, 4}};
  FrameParser parser(Protocol::kMarvelmind);
  const auto frames = parse(parser, encode_marvelmind_distances(distances));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(std::get<DistancesFrame>(frames[0].body) == distances);
  distances.slots.push_back({5, 5});
  EXPECT_THROW(encode_marvelmind_distances(distances), std::invalid_argument);
  distances.slots = {{0, 5}};
  EXPECT_THROW(encode_marvelmind_distances(distances), std::invalid_argument);
}

// Positions (0x0001, 0x0011), beacon positions (0x0002, 0x0012), IMU (0x0003, 0x0005), telemetry
// (0x0006), quality (0x0007), the 64-bit-stamped kinds (0x0081...), a waypoint on packet type
// 0x4A, and a code nobody documents: valid packets we do not use, none of them garbage.
TEST(SerialMarvelmind, EveryOtherPacketWhoseChecksumHoldsIsUnusedNotGarbage) {
  struct Packet {
    std::uint8_t type;
    std::uint16_t code;
    std::size_t size;
  };
  const Packet packets[] = {{0x47, 0x0001, 16},         {0x47, 0x0011, 22},  {0x47, 0x0002, 1 + 4 * 8},
                            {0x47, 0x0012, 1 + 4 * 14}, {0x47, 0x0003, 32},  {0x47, 0x0005, 42},
                            {0x47, 0x0006, 16},         {0x47, 0x0007, 16},  {0x47, 0x0084, 36},
                            {0x4A, 0x0201, 12},         {0x47, 0x7777, 255}, {0x47, 0x0009, 0}};
  FrameParser parser(Protocol::kMarvelmind);
  Bytes line;
  std::uint8_t fill = 0;
  for (const Packet& p : packets) {
    const Bytes packet = encode_marvelmind_raw(p.type, p.code, Bytes(p.size, fill++));
    line.insert(line.end(), packet.begin(), packet.end());
  }
  const Bytes distances = encode_marvelmind_distances(DistancesFrame{});
  line.insert(line.end(), distances.begin(), distances.end());
  EXPECT_EQ(parse(parser, line).size(), 1u);
  EXPECT_EQ(parser.counts().unused_frames, sizeof packets / sizeof packets[0]);
  EXPECT_EQ(parser.counts().garbage_bytes, 0u);
  for (std::size_t i = 0; i < kFrameRejectionCount; ++i) EXPECT_EQ(parser.counts().rejected[i], 0u);
}

// Raw distances have 32 bytes: another size is refused on the header, at once.
TEST(SerialMarvelmind, DistancesOfAnotherSizeAreRefusedAtOnce) {
  FrameParser parser(Protocol::kMarvelmind);
  EXPECT_TRUE(parse(parser, {0xFF, 0x47, 0x04, 0x00, 0x21}).empty());
  EXPECT_EQ(parser.counts().rejections(FrameRejection::kBadLength), 1u);
  EXPECT_EQ(parser.pending_bytes(), 0u);
  EXPECT_TRUE(parse(parser, encode_marvelmind_raw(0x47, 0x0004, Bytes(31, 0))).empty());
  EXPECT_EQ(parser.counts().rejections(FrameRejection::kBadLength), 2u);
  // The same code on the read/write packet type is not raw distances: unused, whatever its size.
  EXPECT_TRUE(parse(parser, encode_marvelmind_raw(0x4A, 0x0004, Bytes(31, 0))).empty());
  EXPECT_EQ(parser.counts().unused_frames, 1u);
}

// Only destination 0xFF and packet types 0x47 and 0x4A start a packet.
TEST(SerialMarvelmind, OtherAddressesAndPacketTypesAreGarbage) {
  Bytes packet = encode_marvelmind_distances(DistancesFrame{});
  packet[1] = 0x48;
  FrameParser parser(Protocol::kMarvelmind);
  EXPECT_TRUE(parse(parser, packet).empty());
  EXPECT_EQ(parser.counts().garbage_bytes, packet.size());
  EXPECT_EQ(parser.counts().rejections(FrameRejection::kGarbage), 1u);
}

// A damaged byte anywhere in a packet: never a frame (one-byte errors are within CRC-16's reach).
TEST(SerialMarvelmind, ADamagedByteAnywhereIsNeverAFrame) {
  DistancesFrame distances;
  distances.stamp_ms = 99;
  distances.slots = {{1, 1}};
  const Bytes good = encode_marvelmind_distances(distances);
  for (std::size_t at = 0; at < good.size(); ++at) {
    for (int bit = 0; bit < 8; ++bit) {
      Bytes bad = good;
      bad[at] = static_cast<std::uint8_t>(bad[at] ^ (1 << bit));
      FrameParser parser(Protocol::kMarvelmind);
      ASSERT_TRUE(parse(parser, bad).empty()) << at << " " << bit;
      ASSERT_EQ(parser.counts().unused_frames, 0u);
    }
  }
}

}  // namespace
}  // namespace beaconloc::serial
