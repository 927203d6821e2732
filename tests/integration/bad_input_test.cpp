// Bad input from the bus, as a faulty gateway or a misconfigured robot would send it, to the
// decoder and localizer processes: every sample gets a typed refusal, counted by reason in the
// participant's Diagnostics; nothing crashes, and good samples around the bad ones still count.
// docs/bad-input.md lists every row with the test that shows it.
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "beaconloc/dds/convert.hpp"
#include "diagnostics_recorder.hpp"
#include "domain_id.hpp"
#include "participants_test.hpp"
#include "process.hpp"
#include "sim/scenario.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class BadInput : public ParticipantsTest {
 protected:
  // Writes the beacon map and waits until the participant has taken it: its message no longer
  // says it waits for one (a localizer that has heard no robot stays degraded for that). What
  // comes next on the other topics is then judged against the map, whatever order the topics
  // would have delivered them in.
  static void send_map(const DiagnosticsRecorder& recorder, const std::string& name,
                       const dds::Writer& map_writer) {
    auto map = dds::to_msg(BeaconMap(sim::default_scenario().beacons), "map");
    ASSERT_TRUE(map_writer->write(&map));
    auto has_map = [](const msg::Diagnostics& r) {
      return !r.participant().empty() && r.message().find("waiting for the beacon map") == std::string::npos;
    };
    const auto d = wait_for_diagnostics(recorder, name, has_map);
    ASSERT_TRUE(has_map(d)) << name << ": " << d.message();
  }
};

TEST_F(BadInput, DecoderRefusesEveryBadTofByReason) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess decoder(command("decoder"), dir_ + "/decoder.log");
  dds::Participant bus(dds_, "test.faulty_gateway");
  auto map_writer = bus.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic);
  auto tof_writer = bus.writer<msg::RawTofPubSubType>(dds::kRawTofTopic);
  ASSERT_TRUE(dds::wait_for_matched_readers({map_writer, tof_writer}, scaled(10s))) << decoder.log();
  ASSERT_NO_FATAL_FAILURE(send_map(diagnostics, kDecoder, map_writer));

  std::uint64_t sequence = 0;
  auto tof = [&](StampNs fire_ns, double tof_s) {
    RawTofSample s;
    s.beacon_id = sim::default_scenario().beacons.front().id;
    s.fire_stamp_ns = fire_ns;
    s.tof_s = tof_s;
    s.beacon_temperature_c = 22.0;
    s.sequence_number = ++sequence;
    return s;
  };
  std::vector<RawTofSample> samples;
  samples.push_back(tof(10 * kNsPerSecond, 0.006));  // good: 2.06 m
  samples.push_back(tof(10 * kNsPerSecond, std::nan("")));
  samples.push_back(tof(10 * kNsPerSecond, std::numeric_limits<double>::infinity()));
  samples.push_back(tof(10 * kNsPerSecond, -0.006));
  samples.push_back(tof(10 * kNsPerSecond, 0.2));  // 69 m: out of range
  auto hot = tof(10 * kNsPerSecond, 0.006);
  hot.beacon_temperature_c = 500.0;
  samples.push_back(hot);
  auto unknown = tof(10 * kNsPerSecond, 0.006);
  unknown.beacon_id = 4242;
  samples.push_back(unknown);
  samples.push_back(samples.front());                 // the same sample again: duplicate
  samples.push_back(tof(9'200'000'000, 0.006));       // 0.8 s before the newest firing: stale
  samples.push_back(tof(100 * kNsPerSecond, 0.006));  // 90 s ahead, alone: a bad stamp, taken as a gap
  samples.push_back(tof(10'400'000'000, 0.006));      // back on the time line: time_jump...
  samples.push_back(tof(10'600'000'000, 0.006));      // ...confirmed by the next firing
  samples.push_back(tof(10'200'000'000, 0.006));      // good, the next slot
  for (const auto& s : samples) {
    auto m = dds::to_msg("robot1", s);
    ASSERT_EQ(tof_writer->write(&m), true);
  }
  // One reader takes them in order: the last one, good, is the 4th accepted.
  const auto d = wait_for_diagnostics(diagnostics, kDecoder,
                                      [](const msg::Diagnostics& r) { return r.accepted() >= 4; });
  print_report(kDecoder, ParticipantReport{d, Liveness::kAlive, 0.0, {}}, std::cout);
  EXPECT_EQ(d.accepted(), 4u);
  EXPECT_EQ(rejected_count(d, "non_finite_tof"), 2u);
  EXPECT_EQ(rejected_count(d, "negative_tof"), 1u);
  EXPECT_EQ(rejected_count(d, "out_of_range_tof"), 1u);
  EXPECT_EQ(rejected_count(d, "bad_temperature"), 1u);
  EXPECT_EQ(rejected_count(d, "unknown_beacon"), 1u);
  EXPECT_EQ(rejected_count(d, "duplicate"), 1u);
  EXPECT_EQ(rejected_count(d, "stale"), 1u);
  EXPECT_EQ(rejected_count(d, "time_jump"), 1u);
  decoder.signal(SIGTERM);
  const auto code = decoder.wait(15s);
  ASSERT_TRUE(code);
  EXPECT_EQ(*code, 0) << decoder.log();
}

TEST_F(BadInput, LocalizerRefusesEveryBadSampleByReason) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess localizer(command("localizer", {"--robot", "robot1"}), dir_ + "/localizer.log");
  dds::Participant bus(dds_, "test.faulty_robot");
  auto map_writer = bus.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic);
  auto odometry_writer = bus.writer<msg::OdometryPubSubType>(dds::kOdometryTopic);
  auto range_writer = bus.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic);
  ASSERT_TRUE(dds::wait_for_matched_readers({map_writer, odometry_writer, range_writer}, scaled(10s)))
      << localizer.log();
  ASSERT_NO_FATAL_FAILURE(send_map(diagnostics, kRangeEkfLocalizer, map_writer));
  const auto beacons = sim::default_scenario().beacons;

  std::uint64_t sequence = 0;
  auto odometry = [&](const std::string& robot, StampNs stamp_ns, std::uint64_t skip = 0) {
    OdometrySample o;
    o.stamp_ns = stamp_ns;
    o.wheel_base_m = 0.33;
    o.wheel_velocity_covariance = 1e-6 * Eigen::Matrix2d::Identity();
    sequence += 1 + skip;
    return dds::to_msg(robot, o, sequence);
  };
  std::uint64_t good_odometry = 0;
  StampNs t = kNsPerSecond;
  for (int i = 0; i < 20; ++i, t += 10 * kNsPerMillisecond, ++good_odometry) {
    auto m = odometry("robot1", t);
    odometry_writer->write(&m);
  }
  const StampNs newest = t - 10 * kNsPerMillisecond;
  auto duplicate = odometry("robot1", newest);
  odometry_writer->write(&duplicate);
  auto back = odometry("robot1", newest - 5 * kNsPerMillisecond);
  odometry_writer->write(&back);
  auto nan = odometry("robot1", t);
  nan.wheel_velocity_left_mps(std::nan(""));
  odometry_writer->write(&nan);
  auto no_base = odometry("robot1", t + 1);
  no_base.wheel_base_m(0.0);
  odometry_writer->write(&no_base);
  OdometrySample robot2;
  robot2.stamp_ns = t;
  robot2.wheel_base_m = 0.33;
  auto other = dds::to_msg("robot2", robot2, 1);  // another robot's own sequence
  odometry_writer->write(&other);
  auto after_gap = odometry("robot1", t, 3);  // three sequence numbers never sent
  odometry_writer->write(&after_gap);
  ++good_odometry;
  t += 10 * kNsPerMillisecond;
  auto far_ahead = odometry("robot1", t, std::uint64_t{1} << 62);  // a new numbering, not 2^62 losses
  odometry_writer->write(&far_ahead);
  ++good_odometry;
  // The ranges are judged against the odometry: it is all taken first (one reader, in order: the
  // last sample, good, makes the count).
  const auto odometry_taken =
      wait_for_diagnostics(diagnostics, kRangeEkfLocalizer,
                           [&](const msg::Diagnostics& d) { return d.accepted() >= good_odometry; });
  ASSERT_EQ(odometry_taken.accepted(), good_odometry) << localizer.log();

  auto range = [&](StampNs stamp_ns, std::uint32_t beacon, std::uint32_t receiver, double range_m) {
    msg::BeaconRange m;
    m.robot_id("robot1");
    m.beacon_id(beacon);
    m.receiver_id(receiver);
    m.stamp_ns(stamp_ns);
    m.range_m(range_m);
    m.variance_m2(1e-4);
    m.quality(1.0f);
    m.association(msg::RANGE_ASSOCIATION_BY_ID);
    return m;
  };
  const std::uint32_t id = beacons.front().id;
  std::vector<msg::BeaconRange> ranges = {
      range(t, id, 0, 2.1),                        // good
      range(t, id, 0, std::nan("")),               // not finite
      range(t, id, 0, -1.0),                       // not positive
      range(t, 4242, 0, 2.1),                      // not in the map
      range(t, id, 7, 2.1),                        // the robot has 3 receivers
      range(t, msg::BEACON_UNIDENTIFIED, 0, 2.1),  // range_ekf needs identified beacons
      range(t - 2 * kNsPerSecond, id, 0, 2.1),     // older than the 600 ms it may be late
      range(t + 3 * kNsPerSecond, id, 0, 2.1),     // a clock jump ahead of the odometry
  };
  // An association the IDL does not define: dropped at the reader's door (dds::CheckedType), not
  // read as identified. Sent before the last one, which the wait below needs.
  ranges.insert(ranges.end() - 1, range(t, id, 0, 2.1));
  (ranges.end() - 2)->association(static_cast<msg::RangeAssociation>(7));
  for (auto& m : ranges) range_writer->write(&m);

  // One reader takes the ranges in order: the last one counts as ahead_of_odometry.
  const auto d = wait_for_diagnostics(diagnostics, kRangeEkfLocalizer, [](const msg::Diagnostics& r) {
    return rejected_count(r, "range.ahead_of_odometry") >= 1;
  });
  print_report("localizer", ParticipantReport{d, Liveness::kAlive, 0.0, {}}, std::cout);
  EXPECT_EQ(d.accepted(), good_odometry + 1);
  EXPECT_EQ(rejected_count(d, "odometry.duplicate_odometry"), 1u);
  EXPECT_EQ(rejected_count(d, "odometry.out_of_order_odometry"), 1u);
  EXPECT_EQ(rejected_count(d, "odometry.non_finite_odometry"), 1u);
  EXPECT_EQ(rejected_count(d, "odometry.invalid_wheel_base"), 1u);
  EXPECT_EQ(rejected_count(d, "odometry.other_robot"), 1u);
  EXPECT_EQ(rejected_count(d, "odometry.lost_increment"), 3u);
  EXPECT_EQ(rejected_count(d, "odometry.sequence_restart"), 1u);
  EXPECT_GE(rejected_count(d, "undecodable_sample"), 1u);
  EXPECT_EQ(rejected_count(d, "range.non_finite_range"), 1u);
  EXPECT_EQ(rejected_count(d, "range.invalid_range"), 1u);
  EXPECT_EQ(rejected_count(d, "range.unknown_beacon"), 1u);
  EXPECT_EQ(rejected_count(d, "range.unknown_receiver"), 1u);
  EXPECT_EQ(rejected_count(d, "range.unassociated_range"), 1u);
  EXPECT_EQ(rejected_count(d, "range.too_late"), 1u);
  EXPECT_EQ(rejected_count(d, "range.ahead_of_odometry"), 1u);
  localizer.signal(SIGTERM);
  const auto code = localizer.wait(15s);
  ASSERT_TRUE(code);
  EXPECT_EQ(*code, 0) << localizer.log();
}

}  // namespace
}  // namespace beaconloc::testing
