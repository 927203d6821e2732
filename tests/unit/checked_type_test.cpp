// Every enumeration and string on the bus is checked at the reader's door (dds::CheckedType): Fast
// CDR reads an enum as a 32-bit integer and casts it unchecked, so a hostile or corrupted sample
// could carry a status no switch lists (the monitor once indexed its status names at -1), and a
// string with a newline or an escape sequence would forge the monitor's lines and the CSV rows.
// No participant: no DDS traffic.
#include <beaconlocPubSubTypes.h>
#include <fastdds/rtps/common/SerializedPayload.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>

#include "beaconloc/dds/checked_type.hpp"

namespace beaconloc::dds {
namespace {

// Sends `m` through the type support and reads it back: whether the reader took it, and the
// refusals counted.
template <class PubSubType>
std::pair<bool, std::uint64_t> round_trip(const typename PubSubType::type& m) {
  std::atomic<std::uint64_t> refused{0};
  CheckedType<PubSubType> type(&refused);
  eprosima::fastrtps::rtps::SerializedPayload_t wire(type.m_typeSize + 4096);
  auto sent = m;
  EXPECT_TRUE(type.serialize(&sent, &wire));
  typename PubSubType::type received;
  const bool taken = type.deserialize(&wire, &received);
  return {taken, refused.load()};
}

constexpr std::uint32_t kUndefined[] = {3, 7, 0x7FFFFFFF, 0xFFFFFFFF};

TEST(CheckedType, ADiagnosticsStatusTheIdlDoesNotDefineIsRefusedAndCounted) {
  msg::Diagnostics d;
  d.participant("p");
  for (auto s : {msg::PARTICIPANT_STATUS_OK, msg::PARTICIPANT_STATUS_DEGRADED, msg::PARTICIPANT_STATUS_ERROR}) {
    d.status(s);
    EXPECT_EQ(round_trip<msg::DiagnosticsPubSubType>(d), std::make_pair(true, std::uint64_t{0}));
  }
  for (std::uint32_t v : kUndefined) {
    d.status(static_cast<msg::ParticipantStatus>(v));
    EXPECT_EQ(round_trip<msg::DiagnosticsPubSubType>(d), std::make_pair(false, std::uint64_t{1})) << v;
  }
}

TEST(CheckedType, APoseStatusTheIdlDoesNotDefineIsRefusedAndCounted) {
  msg::PoseEstimate p;
  p.robot_id("r");
  for (auto s : {msg::POSE_STATUS_INITIALIZING, msg::POSE_STATUS_OK, msg::POSE_STATUS_DEGRADED,
                 msg::POSE_STATUS_LOST}) {
    p.status(s);
    EXPECT_EQ(round_trip<msg::PoseEstimatePubSubType>(p), std::make_pair(true, std::uint64_t{0}));
  }
  for (std::uint32_t v : {std::uint32_t{4}, kUndefined[1], kUndefined[3]}) {
    p.status(static_cast<msg::PoseStatus>(v));
    EXPECT_EQ(round_trip<msg::PoseEstimatePubSubType>(p), std::make_pair(false, std::uint64_t{1})) << v;
  }
}

TEST(CheckedType, ARangeAssociationTheIdlDoesNotDefineIsRefusedNotReadAsIdentified) {
  msg::BeaconRange r;
  r.robot_id("r");
  for (auto a : {msg::RANGE_ASSOCIATION_BY_ID, msg::RANGE_ASSOCIATION_UNASSOCIATED}) {
    r.association(a);
    EXPECT_EQ(round_trip<msg::BeaconRangePubSubType>(r), std::make_pair(true, std::uint64_t{0}));
  }
  for (std::uint32_t v : {std::uint32_t{2}, kUndefined[1], kUndefined[3]}) {
    r.association(static_cast<msg::RangeAssociation>(v));
    EXPECT_EQ(round_trip<msg::BeaconRangePubSubType>(r), std::make_pair(false, std::uint64_t{1})) << v;
  }
}

TEST(CheckedType, APulseMarkTheIdlDoesNotDefineIsRefusedNotReadAsADoubleBurst) {
  msg::PulseArrival p;
  p.robot_id("r");
  for (auto m : {msg::PULSE_MARK_NOT_REPORTED, msg::PULSE_MARK_SINGLE, msg::PULSE_MARK_DOUBLE}) {
    p.mark(m);
    EXPECT_EQ(round_trip<msg::PulseArrivalPubSubType>(p), std::make_pair(true, std::uint64_t{0}));
  }
  for (std::uint32_t v : {std::uint32_t{3}, kUndefined[1], kUndefined[3]}) {
    p.mark(static_cast<msg::PulseMark>(v));
    EXPECT_EQ(round_trip<msg::PulseArrivalPubSubType>(p), std::make_pair(false, std::uint64_t{1})) << v;
  }
}

TEST(CheckedType, ABeaconFrameTheIdlDoesNotDefineIsRefusedNotReadAsAMapPosition) {
  msg::BeaconMap m;
  m.frame_id("map");
  m.beacons().resize(2);
  for (auto f : {msg::BEACON_FRAME_MAP, msg::BEACON_FRAME_GROUP}) {
    m.beacons()[1].frame(f);
    EXPECT_EQ(round_trip<msg::BeaconMapPubSubType>(m), std::make_pair(true, std::uint64_t{0}));
  }
  for (std::uint32_t v : {std::uint32_t{2}, kUndefined[1], kUndefined[3]}) {
    m.beacons()[1].frame(static_cast<msg::BeaconFrame>(v));
    EXPECT_EQ(round_trip<msg::BeaconMapPubSubType>(m), std::make_pair(false, std::uint64_t{1})) << v;
  }
}

TEST(CheckedType, AnEstimatorStateValueNameThatBreaksACsvCellIsRefused) {
  msg::EstimatorState s;
  s.robot_id("r");
  s.estimator("kleeman_iekf");
  msg::EstimatorStateValue v;
  v.name("speed_of_sound_mps");
  s.values().push_back(v);
  EXPECT_EQ(round_trip<msg::EstimatorStatePubSubType>(s), std::make_pair(true, std::uint64_t{0}));
  for (const char* bad : {"speed,of_sound", "speed\nx", "\"s\""}) {
    s.values()[0].name(bad);
    EXPECT_EQ(round_trip<msg::EstimatorStatePubSubType>(s), std::make_pair(false, std::uint64_t{1})) << bad;
  }
}

TEST(CheckedType, AStringWithAControlCharacterOrANameThatBreaksACsvCellIsRefusedOnEveryTopic) {
  const std::string forged[] = {"robot1\nmonitor: 0 poses", "\x1b[2Jr", "r\x7f", "r\tb", "r\xc2\x9b" "2J"};
  for (const std::string& bad : forged) {
    msg::Diagnostics d;
    d.participant("p");
    d.message(bad);
    EXPECT_EQ(round_trip<msg::DiagnosticsPubSubType>(d), std::make_pair(false, std::uint64_t{1}));
    d.message("fine");
    d.robots_localized({"a", bad});
    EXPECT_EQ(round_trip<msg::DiagnosticsPubSubType>(d), std::make_pair(false, std::uint64_t{1}));
    msg::PoseEstimate p;
    p.robot_id(bad);
    EXPECT_EQ(round_trip<msg::PoseEstimatePubSubType>(p), std::make_pair(false, std::uint64_t{1}));
    msg::Odometry o;
    o.robot_id(bad);
    EXPECT_EQ(round_trip<msg::OdometryPubSubType>(o), std::make_pair(false, std::uint64_t{1}));
    msg::RawTof t;
    t.robot_id(bad);
    EXPECT_EQ(round_trip<msg::RawTofPubSubType>(t), std::make_pair(false, std::uint64_t{1}));
    msg::BeaconMap m;
    m.frame_id(bad);
    EXPECT_EQ(round_trip<msg::BeaconMapPubSubType>(m), std::make_pair(false, std::uint64_t{1}));
    msg::InitialPose i;
    i.robot_id(bad);
    EXPECT_EQ(round_trip<msg::InitialPosePubSubType>(i), std::make_pair(false, std::uint64_t{1}));
    msg::LaserScan l;
    l.robot_id(bad);
    EXPECT_EQ(round_trip<msg::LaserScanPubSubType>(l), std::make_pair(false, std::uint64_t{1}));
    msg::BeaconRange r;
    r.robot_id(bad);
    EXPECT_EQ(round_trip<msg::BeaconRangePubSubType>(r), std::make_pair(false, std::uint64_t{1}));
    p.robot_id("r");
    p.estimator(bad);
    EXPECT_EQ(round_trip<msg::PoseEstimatePubSubType>(p), std::make_pair(false, std::uint64_t{1}));
    d.robots_localized({});
    d.participant(bad);
    EXPECT_EQ(round_trip<msg::DiagnosticsPubSubType>(d), std::make_pair(false, std::uint64_t{1}));
    d.participant("p");
    d.rejected({msg::RejectionCount()});
    d.rejected()[0].reason(bad);
    EXPECT_EQ(round_trip<msg::DiagnosticsPubSubType>(d), std::make_pair(false, std::uint64_t{1}));
  }
  // A name that would shift the columns of a CSV file (written unquoted).
  for (const std::string& bad : {std::string("r,1"), std::string("r\"1")}) {
    msg::PoseEstimate p;
    p.robot_id(bad);
    EXPECT_EQ(round_trip<msg::PoseEstimatePubSubType>(p), std::make_pair(false, std::uint64_t{1})) << bad;
    msg::Odometry o;
    o.robot_id(bad);
    EXPECT_EQ(round_trip<msg::OdometryPubSubType>(o), std::make_pair(false, std::uint64_t{1})) << bad;
  }
  // A message may hold commas and quotes: it is text, not a cell.
  msg::Diagnostics text;
  text.participant("p");
  text.message("1 robot(s), worst pose status \"ok\"");
  EXPECT_EQ(round_trip<msg::DiagnosticsPubSubType>(text), std::make_pair(true, std::uint64_t{0}));
  // UTF-8 and punctuation are names like any other.
  msg::PoseEstimate p;
  p.robot_id("röbot-7/base_link");
  EXPECT_EQ(round_trip<msg::PoseEstimatePubSubType>(p), std::make_pair(true, std::uint64_t{0}));
}

}  // namespace
}  // namespace beaconloc::dds
