// Recordings of the bus (replay/bus_recording.hpp): what is written is read back by ReplaySource
// as the very same samples, numbers and all; rows that are no sample are refused and counted, the
// others kept; a recording that is two things at once, or a robot with a hole, is refused.
#include "replay/bus_recording.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "replay/replay_source.hpp"

namespace beaconloc {
namespace {

class BusRecording : public ::testing::Test {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/beaconloc-bus-XXXXXX";
    ASSERT_NE(::mkdtemp(dir), nullptr);
    dir_ = dir;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write_file(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ + "/" + name) << text;
  }
  static BeaconMap map() {
    return BeaconMap(std::vector<Beacon>{{1, {0.1 + 0.2, -1.0 / 3.0, 2.011}, 0}, {2, {3.0, 1e-7, 2.5}, 0}});
  }
  std::string dir_;
};

TEST_F(BusRecording, WhatIsWrittenIsReplayedExactly) {
  OdometrySample o;
  o.stamp_ns = 10'000'000;
  o.wheel_velocity_right_mps = 1.0 / 3.0;
  o.wheel_velocity_left_mps = -0.1 - 0.2;
  o.wheel_base_m = 0.33;
  o.wheel_velocity_covariance << 1e-5 / 3.0, -2.5e-7, -2.5e-7, std::nextafter(1e-5, 1.0);
  RawTofSample t;
  t.fire_stamp_ns = 5'000'000;
  t.beacon_id = kBeaconUnidentified;  // an anonymous beacon travels as such
  t.receiver_id = 2;
  t.tof_s = 0.0061233383713133;
  t.beacon_temperature_c = 21.7;
  t.sequence_number = 7;
  RawTofSample negative = t;  // judged by the decoder, not by the replay
  negative.tof_s = -1e-3;
  negative.beacon_id = 2;
  negative.fire_stamp_ns = 20'000'000;
  LaserScanSample s;
  s.stamp_ns = 15'000'000;
  s.angle_min_rad = -1.5707964f;
  s.angle_increment_rad = 0.017453292f;
  s.range_min_m = 0.1f;
  s.range_max_m = 30.0f;
  s.ranges_m = {1.25f, std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN(), 0.3f};
  ReceiverArray receivers = ReceiverArray::on_circle(0.19, 3);
  receivers.receiver_height_m = 0.05;
  {
    BusRecordingWriter w(dir_, false);
    w.write_beacons(map());
    w.write_receivers(receivers);
    w.write(o);
    w.write(t);
    w.write(negative);
    w.write(s);
  }
  const ReplaySource replay(dir_);
  EXPECT_EQ(replay.load_counts().rejected_total(), 0u);
  const auto r = replay.receivers();
  ASSERT_EQ(r.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(r.receivers_base_m[i], receivers.receivers_base_m[i]);
  EXPECT_EQ(r.receiver_height_m, 0.05);
  ASSERT_EQ(replay.beacon_map().beacons().size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(replay.beacon_map().beacons()[i].position_map_m, map().beacons()[i].position_map_m);
  }
  std::vector<SourceEvent> events;
  ReplaySource copy(dir_);
  copy.advance(std::numeric_limits<StampNs>::max(), events);
  ASSERT_EQ(events.size(), 4u);
  // In stamp order: odometry at 10 ms, the TOF's arrival at 5 + 6.12 ms, the scan at 15 ms, the
  // negative TOF's at 20 - 1 ms.
  EXPECT_EQ(events[0].kind, SourceEvent::Kind::kOdometry);
  EXPECT_EQ(events[0].odometry.stamp_ns, o.stamp_ns);
  EXPECT_EQ(events[0].odometry.wheel_velocity_right_mps, o.wheel_velocity_right_mps);
  EXPECT_EQ(events[0].odometry.wheel_velocity_left_mps, o.wheel_velocity_left_mps);
  EXPECT_EQ(events[0].odometry.wheel_base_m, o.wheel_base_m);
  EXPECT_EQ(events[0].odometry.wheel_velocity_covariance, o.wheel_velocity_covariance);
  EXPECT_EQ(events[1].kind, SourceEvent::Kind::kTof);
  EXPECT_EQ(events[1].tof.fire_stamp_ns, t.fire_stamp_ns);
  EXPECT_EQ(events[1].tof.beacon_id, kBeaconUnidentified);
  EXPECT_EQ(events[1].tof.receiver_id, 2u);
  EXPECT_EQ(events[1].tof.tof_s, t.tof_s);
  EXPECT_EQ(events[1].tof.beacon_temperature_c, t.beacon_temperature_c);
  EXPECT_EQ(events[1].tof.sequence_number, 7u);
  EXPECT_EQ(events[1].stamp_ns, t.fire_stamp_ns + s_to_ns(t.tof_s));
  EXPECT_EQ(events[2].kind, SourceEvent::Kind::kLaserScan);
  EXPECT_EQ(events[2].scan.angle_min_rad, s.angle_min_rad);
  EXPECT_EQ(events[2].scan.angle_increment_rad, s.angle_increment_rad);
  ASSERT_EQ(events[2].scan.ranges_m.size(), 4u);
  EXPECT_EQ(events[2].scan.ranges_m[0], 1.25f);
  EXPECT_TRUE(std::isinf(events[2].scan.ranges_m[1]));
  EXPECT_TRUE(std::isnan(events[2].scan.ranges_m[2]));
  EXPECT_EQ(events[2].scan.ranges_m[3], 0.3f);
  EXPECT_EQ(events[3].kind, SourceEvent::Kind::kTof);
  EXPECT_EQ(events[3].tof.tof_s, -1e-3);  // travels on for the decoder to refuse
}

TEST_F(BusRecording, RowsThatAreNoSampleAreRefusedAndCountedTheOthersKept) {
  BusRecordingWriter(dir_, false).write_beacons(map());
  write_file("odometry.csv",
             std::string(bus_recording::kOdometryHeader) +
                 "\n10000000,0.1,0.1,0.33,1e-5,0,1e-5\n"
                 "20000000,nan,0.1,0.33,1e-5,0,1e-5\n"  // a NaN the bus carried: no decimal number
                 "-5,0.1,0.1,0.33,1e-5,0,1e-5\n"        // a stamp before the epoch
                 "30000000,0.1,0.1\n"                   // cut short (a kill mid-row, were rows not whole)
                 "40000000,0.1,0.1,0.33,1e-5,0,1e-5\n");
  write_file("tof.csv", std::string(bus_recording::kTofHeader) +
                            "\n5000000,1,0,0.006,20,0\n"
                            "6000000,4294967296,0,0.006,20,1\n"  // an id beyond 32 bits
                            "7000000,1,0,7200,20,2\n");          // a TOF of two hours
  const ReplaySource replay(dir_);
  const RejectionCounter& c = replay.load_counts();
  EXPECT_EQ(c.rejected("odometry.malformed_row"), 2u);
  EXPECT_EQ(c.rejected("odometry.invalid_stamp_ns"), 1u);
  EXPECT_EQ(c.rejected("tof.invalid_beacon_id"), 1u);
  EXPECT_EQ(c.rejected("tof.invalid_tof_s"), 1u);
  EXPECT_EQ(replay.event_count(), 3u);  // two odometry rows and one TOF kept
  EXPECT_FALSE(replay.load_problems().empty());
}

TEST_F(BusRecording, ARecordingThatIsTwoThingsOrARobotWithAHoleIsRefused) {
  BusRecordingWriter(dir_, false).write_beacons(map());
  write_file("odometry.csv",
             std::string(bus_recording::kOdometryHeader) + "\n10000000,0.1,0.1,0.33,1e-5,0,1e-5\n");
  write_file("odom.csv", "t_s,dt_s,v_mps,omega_radps\n0,0.01,0.1,0\n");
  EXPECT_THROW(ReplaySource{dir_}, ReplayError);
  std::filesystem::remove(dir_ + "/odom.csv");
  write_file("receivers.csv", std::string(bus_recording::kReceiversHeader) + "\n0,0.1,0,0\n2,0,0.1,0\n");
  try {
    ReplaySource replay(dir_);
    FAIL() << "receivers 0 and 2 without 1 were taken";
  } catch (const ReplayError& e) {
    EXPECT_NE(std::string(e.what()).find("receiver 2 where 1 comes next"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace beaconloc
