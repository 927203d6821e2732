// The two checksums against their catalogue check values, and the stable names of the parser's
// refusals (plugins/gateway/serial/crc16.hpp, frame_rejection.hpp).
#include "crc16.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <sstream>
#include <vector>

#include "frame_encoder.hpp"
#include "frame_rejection.hpp"

namespace beaconloc::serial {
namespace {

const std::uint8_t kCheck[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};

TEST(SerialCrc16, CcittFalseGivesItsCheckValue) {
  EXPECT_EQ(crc16_ccitt_false(kCheck, sizeof kCheck), 0x29B1);
}

TEST(SerialCrc16, ModbusGivesItsCheckValue) { EXPECT_EQ(crc16_modbus(kCheck, sizeof kCheck), 0x4B37); }

TEST(SerialCrc16, EmptyInputIsTheInitialValue) {
  EXPECT_EQ(crc16_ccitt_false(nullptr, 0), 0xFFFF);
  EXPECT_EQ(crc16_modbus(nullptr, 0), 0xFFFF);
}

// Marvelmind's parsers (marvelmind.c, ArduPilot) check a packet by its CRC over everything,
// checksum included, being 0: true of CRC-16/MODBUS sent low byte first.
TEST(SerialCrc16, ModbusOverAWholePacketSentLowByteFirstIsZero) {
  const std::vector<std::uint8_t> packet =
      encode_marvelmind_raw(0x47, 0x0001, std::vector<std::uint8_t>(16, 0x5A));
  EXPECT_EQ(crc16_modbus(packet.data(), packet.size()), 0);
}

TEST(SerialFrameRejection, EveryReasonHasItsStableSnakeCaseName) {
  const char* expected[] = {"garbage",         "bad_checksum",      "bad_length", "unknown_type",
                            "unknown_version", "reserved_bits_set", "duplicate",  "truncated"};
  ASSERT_EQ(sizeof expected / sizeof expected[0], kFrameRejectionCount);
  for (std::size_t i = 0; i < kFrameRejectionCount; ++i) {
    EXPECT_STREQ(to_string(static_cast<FrameRejection>(i)), expected[i]);
  }
  std::ostringstream out;
  out << FrameRejection::kBadChecksum;
  EXPECT_EQ(out.str(), "bad_checksum");
}

}  // namespace
}  // namespace beaconloc::serial
