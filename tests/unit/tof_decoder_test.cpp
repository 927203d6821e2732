// The decoder core: range from TOF with the paper's speed of sound, and a typed, counted
// rejection for each kind of bad input.
#include "tof_decoder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc {
namespace {

RawTofSample good(std::uint64_t seq, StampNs fire_ns = 1'000'000'000) {
  RawTofSample s;
  s.beacon_id = 1;
  s.receiver_id = 2;
  s.fire_stamp_ns = fire_ns;
  s.tof_s = 0.006;
  s.beacon_temperature_c = 22.0;
  s.sequence_number = seq;
  return s;
}

TofDecoder decoder_with_map() {
  TofDecoder d;
  d.set_beacon_map(BeaconMap({{1, {0.0, 0.0, 2.011}, 0}, {2, {1.5, 0.0, 2.011}, 0}}));
  return d;
}

TEST(TofDecoder, RangeUsesTheSpeedOfSoundOfTheReportedTemperature) {
  EXPECT_NEAR(speed_of_sound_mps(0.0), 20.05 * std::sqrt(273.16), 1e-12);
  auto d = decoder_with_map();
  auto s = good(1);
  s.beacon_temperature_c = 30.0;
  const auto out = d.decode("r1", s);
  ASSERT_TRUE(out.range);
  EXPECT_NEAR(out.range->range.range_m, 0.006 * 20.05 * std::sqrt(303.16), 1e-12);
  EXPECT_EQ(out.range->range.stamp_ns, s.fire_stamp_ns + 6'000'000);  // arrival of the pulse
  EXPECT_EQ(out.range->range.beacon_id, 1u);
  EXPECT_EQ(out.range->range.receiver_id, 2u);
  EXPECT_NEAR(out.range->range.variance_m2, 1e-4, 1e-15);
  EXPECT_EQ(d.counts().accepted(), 1u);
}

TEST(TofDecoder, CountsEveryRejectionByReason) {
  auto d = decoder_with_map();
  std::uint64_t seq = 0;
  auto expect_rejected = [&](RawTofSample s, Rejection why) {
    const auto out = d.decode("r1", s);
    EXPECT_FALSE(out.range);
    ASSERT_TRUE(out.rejection);
    EXPECT_EQ(*out.rejection, why) << to_string(why);
  };
  auto s = good(++seq);
  s.tof_s = std::nan("");
  expect_rejected(s, Rejection::kNonFiniteTof);
  s = good(++seq);
  s.tof_s = std::numeric_limits<double>::infinity();
  expect_rejected(s, Rejection::kNonFiniteTof);
  s = good(++seq);
  s.tof_s = -0.004;
  expect_rejected(s, Rejection::kNegativeTof);
  s = good(++seq);
  s.tof_s = 0.5;  // 172 m
  expect_rejected(s, Rejection::kOutOfRangeTof);
  s = good(++seq);
  s.tof_s = 1e-5;  // 3.4 mm: closer than any ceiling beacon can be
  expect_rejected(s, Rejection::kOutOfRangeTof);
  s = good(++seq);
  s.beacon_temperature_c = std::nan("");
  expect_rejected(s, Rejection::kBadTemperature);
  s = good(++seq);
  s.beacon_temperature_c = 400.0;
  expect_rejected(s, Rejection::kBadTemperature);
  s = good(++seq);
  s.beacon_id = 99;
  expect_rejected(s, Rejection::kUnknownBeacon);

  ASSERT_TRUE(d.decode("r1", good(++seq, 5'000'000'000)).range);      // newest firing: 5 s
  expect_rejected(good(++seq, 4'000'000'000), Rejection::kStaleTof);  // 1 s older than newest
  const auto dup = good(++seq, 4'900'000'000);
  ASSERT_TRUE(d.decode("r1", dup).range);  // 100 ms out of order: still useful, accepted
  expect_rejected(dup, Rejection::kDuplicateTof);

  // Before the map: held, and refused only when it ages out (or overflows the backlog).
  TofDecoder no_map;
  EXPECT_TRUE(no_map.decode("r1", good(1, 1'000'000'000)).deferred);
  EXPECT_TRUE(no_map.decode("r1", good(2, 1'700'000'000)).deferred);  // the first is now 700 ms old
  EXPECT_EQ(no_map.counts().rejected("no_beacon_map"), 1u);
  const auto held = no_map.set_beacon_map(BeaconMap({{1, {0.0, 0.0, 2.011}, 0}}));
  ASSERT_EQ(held.size(), 1u);  // the second one, decoded once the map came
  EXPECT_EQ(held[0].source_sequence_number, 2u);
  EXPECT_EQ(held[0].robot_id, "r1");
  EXPECT_EQ(no_map.counts().accepted(), 1u);

  const auto& c = d.counts();
  EXPECT_EQ(c.rejected("non_finite_tof"), 2u);
  EXPECT_EQ(c.rejected("negative_tof"), 1u);
  EXPECT_EQ(c.rejected("out_of_range_tof"), 2u);
  EXPECT_EQ(c.rejected("bad_temperature"), 2u);
  EXPECT_EQ(c.rejected("unknown_beacon"), 1u);
  EXPECT_EQ(c.rejected("stale"), 1u);
  EXPECT_EQ(c.rejected("duplicate"), 1u);
  EXPECT_EQ(c.rejected_total(), 10u);
  EXPECT_EQ(c.accepted(), 2u);
}

// Gaps forwards are taken (beacons go unheard for seconds). One TOF stamped far ahead (a bad
// stamp) does not make the good TOFs after it stale for ever: the first one back on the robot's
// time line is refused (time_jump) and the next firing confirms the return. A clock stepping
// back is followed the same way. Each costs one firing, counted.
TEST(TofDecoder, AOneOffStampFarAheadDoesNotStallTheDecoderAndAClockJumpBackIsFollowed) {
  auto d = decoder_with_map();
  std::uint64_t seq = 0;
  auto decoded = [&](StampNs fire_ns) { return d.decode("r1", good(++seq, fire_ns)).range.has_value(); };
  EXPECT_TRUE(decoded(5'000'000'000));
  EXPECT_TRUE(decoded(100'000'000'000));  // 95 s ahead: a gap or a bad stamp, taken
  EXPECT_FALSE(decoded(5'200'000'000));   // far behind it...
  EXPECT_TRUE(decoded(5'400'000'000));    // ...and confirmed: back on the robot's time line
  EXPECT_TRUE(decoded(60'000'000'000));   // a 55 s gap
  EXPECT_TRUE(decoded(60'200'000'000));
  EXPECT_FALSE(decoded(5'600'000'000));  // the old time line is gone
  EXPECT_FALSE(decoded(1'000'000'000));  // the clock stepped back 59 s (a restarted replay)...
  EXPECT_TRUE(decoded(1'200'000'000));   // ...confirmed
  EXPECT_EQ(d.counts().rejected("time_jump"), 3u);
  EXPECT_EQ(d.counts().rejected("stale"), 0u);
  EXPECT_EQ(d.counts().accepted(), 6u);
}

TEST(TofDecoder, StalenessIsPerRobot) {
  auto d = decoder_with_map();
  ASSERT_TRUE(d.decode("r1", good(1, 9'000'000'000)).range);
  EXPECT_TRUE(d.decode("r2", good(1, 1'000'000'000)).range);  // another robot's own time line
}

TEST(TofDecoder, AnonymousPulsesPassUnassociated) {
  auto d = decoder_with_map();
  auto s = good(1);
  s.beacon_id = kBeaconUnidentified;
  const auto out = d.decode("r1", s);
  ASSERT_TRUE(out.range);
  EXPECT_FALSE(out.range->associated);
}

}  // namespace
}  // namespace beaconloc
