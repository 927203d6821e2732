// Inputs fuzz_decoder_input (tests/fuzz, docs/fuzzing.md) found on the wire side of the
// decoder: a RawTof payload the generated type support cannot read must be refused and counted,
// not thrown out of Fast DDS's reader (std::terminate). No participant: no DDS traffic.
#include <beaconlocPubSubTypes.h>
#include <fastcdr/exceptions/Exception.h>
#include <fastdds/rtps/common/SerializedPayload.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstring>
#include <vector>

#include "beaconloc/dds/checked_type.hpp"
#include "beaconloc/dds/convert.hpp"

namespace beaconloc::dds {
namespace {

using Payload = eprosima::fastrtps::rtps::SerializedPayload_t;

// The bytes as Fast DDS hands a received sample to the type support (no copy: it owns memory).
void fill(Payload& p, const std::vector<std::uint8_t>& bytes) {
  p.reserve(static_cast<std::uint32_t>(bytes.size()));
  std::memcpy(p.data, bytes.data(), bytes.size());
  p.length = static_cast<std::uint32_t>(bytes.size());
}

TEST(FuzzRegression, UnreadableRawTofPayloadIsRefusedAndCountedNotThrown) {
  // A first byte that is not 0, and an encapsulation that is not plain CDR (0x0007: XCDR2).
  for (const std::vector<std::uint8_t>& bytes :
       {std::vector<std::uint8_t>{0x01, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 'r', 0x00},
        std::vector<std::uint8_t>{0x00, 0x07, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 'r', 0x00}}) {
    Payload payload;
    fill(payload, bytes);
    msg::RawTof m;
    msg::RawTofPubSubType generated;
    EXPECT_THROW(generated.deserialize(&payload, &m), eprosima::fastcdr::exception::Exception);
    std::atomic<std::uint64_t> refused{0};
    CheckedType<msg::RawTofPubSubType> checked(&refused);
    EXPECT_FALSE(checked.deserialize(&payload, &m));
    EXPECT_EQ(refused.load(), 1u);
  }
  // Too short: refused (the generated code returns false), counted the same way.
  Payload short_payload;
  fill(short_payload, {0x00, 0x01, 0x00, 0x00, 0x09});
  std::atomic<std::uint64_t> refused{0};
  CheckedType<msg::RawTofPubSubType> checked(&refused);
  msg::RawTof m;
  EXPECT_FALSE(checked.deserialize(&short_payload, &m));
  EXPECT_EQ(refused.load(), 1u);
  // A sample it can read still decodes, and counts nothing.
  RawTofSample s;
  s.beacon_id = 3;
  s.fire_stamp_ns = 123'456'789;
  s.tof_s = 0.0073;
  s.beacon_temperature_c = 21.5;
  s.sequence_number = 42;
  msg::RawTof sent = to_msg("robot_0", s);
  Payload wire(checked.m_typeSize);
  ASSERT_TRUE(checked.serialize(&sent, &wire));
  msg::RawTof received;
  ASSERT_TRUE(checked.deserialize(&wire, &received));
  EXPECT_EQ(received.robot_id(), "robot_0");
  EXPECT_EQ(from_msg(received).fire_stamp_ns, s.fire_stamp_ns);
  EXPECT_EQ(refused.load(), 1u);
}

}  // namespace
}  // namespace beaconloc::dds
