// The replay source: the fixture and the shared recordings load; rows become the bus's samples
// exactly; bad rows are refused and counted with their file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "beaconloc/core/speed_of_sound.hpp"
#include "replay/replay_source.hpp"

namespace beaconloc {
namespace {

const std::string kFixture = std::string(BEACONLOC_SOURCE_DIR) + "/tests/data/tuc_labyrinth_30s";
const std::string kShared = std::string(BEACONLOC_SOURCE_DIR) + "/../shared/datasets";

std::vector<SourceEvent> everything(ReplaySource& r) {
  std::vector<SourceEvent> out;
  r.advance(r.last_stamp_ns(), out);
  return out;
}

TEST(Replay, FixtureBecomesOdometryRangesAndTruthInStampOrder) {
  ReplaySource replay(kFixture);
  EXPECT_EQ(replay.beacon_map().size(), 4u);
  EXPECT_EQ(replay.load_counts().rejected_total(), 0u);
  const auto events = everything(replay);
  EXPECT_TRUE(replay.exhausted());
  std::map<SourceEvent::Kind, int> n;
  for (std::size_t i = 0; i < events.size(); ++i) {
    ++n[events[i].kind];
    if (i > 0) {
      ASSERT_LE(events[i - 1].stamp_ns, events[i].stamp_ns);
    }
  }
  EXPECT_EQ(n[SourceEvent::Kind::kOdometry], 233);
  EXPECT_EQ(n[SourceEvent::Kind::kTof], 233);
  EXPECT_EQ(n[SourceEvent::Kind::kTruth], 233);
  EXPECT_FALSE(replay.has_truth_yaw());
}

TEST(Replay, RowsConvertExactly) {
  const std::string dir = ::testing::TempDir() + "/replay_exact";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/beacons.csv") << "beacon_id,x_m,y_m,z_m\n7,1,2,0\n";
  std::ofstream(dir + "/odom.csv") << "t_s,dt_s,v_mps,omega_radps\n10.0,0.2,0.8,0.1\n";
  std::ofstream(dir + "/ranges.csv") << "t_s,beacon_id,range_m\n10.1,7,12.5\n";
  std::ofstream(dir + "/gt.csv") << "t_s,x_m,y_m,yaw_rad\n10.0,1,1,4.0\n";
  ReplayOptions options;
  options.wheel_base_m = 0.5;
  ReplaySource replay(dir, options);
  const auto events = everything(replay);
  ASSERT_EQ(events.size(), 3u);
  const auto& gt = events[0];
  EXPECT_EQ(gt.kind, SourceEvent::Kind::kTruth);
  EXPECT_NEAR(gt.truth_map_base.z(), 4.0 - 2 * M_PI, 1e-12);
  const auto& range = events[1];
  EXPECT_EQ(range.stamp_ns, 10'100'000'000);
  EXPECT_EQ(range.tof.fire_stamp_ns + s_to_ns(range.tof.tof_s), range.stamp_ns);
  EXPECT_NEAR(speed_of_sound_mps(range.tof.beacon_temperature_c) * range.tof.tof_s, 12.5, 1e-12);
  const auto& odo = events[2];
  EXPECT_EQ(odo.stamp_ns, 10'200'000'000);  // end of the interval
  const double v = (odo.odometry.wheel_velocity_right_mps + odo.odometry.wheel_velocity_left_mps) / 2;
  const double w = (odo.odometry.wheel_velocity_right_mps - odo.odometry.wheel_velocity_left_mps) /
                   odo.odometry.wheel_base_m;
  EXPECT_NEAR(v, 0.8, 1e-12);
  EXPECT_NEAR(w, 0.1, 1e-12);
}

TEST(Replay, BadRowsAreRefusedAndCountedNotRepaired) {
  const std::string dir = ::testing::TempDir() + "/replay_bad";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/beacons.csv") << "beacon_id,x_m,y_m,z_m\n1,0,0,0\n";
  std::ofstream(dir + "/odom.csv") << "t_s,dt_s,v_mps,omega_radps\n"
                                      "1.0,0.1,0.5,0\n"
                                      "1.1,0.1,nan,0\n"   // not finite
                                      "1.2,0.1,0.5\n"     // a column short
                                      "1.05,0.1,0.5,0\n"  // ends before the previous one
                                      "1.3,-0.1,0.5,0\n"  // negative interval
                                      "1.4,0.1,0.5,0\n";
  std::ofstream(dir + "/ranges.csv")
      << "t_s,beacon_id,range_m\n1.0,1,3.0\n1.1,abc,3.0\n1.2,1.5,3.0\n0.9,1,3.1\n";
  std::ofstream(dir + "/gt.csv") << "t_s,x_m,y_m\n1.0,0,0\n1.0,0,0\n";
  ReplaySource replay(dir);
  const auto& c = replay.load_counts();
  EXPECT_EQ(c.rejected("odom.malformed_row"), 2u);
  EXPECT_EQ(c.rejected("odom.out_of_order_row"), 1u);
  EXPECT_EQ(c.rejected("odom.invalid_value"), 1u);
  EXPECT_EQ(c.rejected("ranges.malformed_row"), 2u);
  EXPECT_EQ(c.rejected("gt.out_of_order_row"), 1u);
  EXPECT_EQ(replay.load_notes().size(), 1u);  // the 0.9 s range, filed late: replayed in order
  ASSERT_FALSE(replay.load_problems().empty());
  EXPECT_NE(replay.load_problems().front().find("odom.csv:3"), std::string::npos);
  const auto events = everything(replay);
  int odometry = 0, ranges = 0;
  for (const auto& e : events) {
    odometry += e.kind == SourceEvent::Kind::kOdometry;
    ranges += e.kind == SourceEvent::Kind::kTof;
  }
  EXPECT_EQ(odometry, 2);
  EXPECT_EQ(ranges, 2);
  EXPECT_EQ(events.front().kind, SourceEvent::Kind::kTof);  // the range at 0.9 s comes first
}

TEST(Replay, MissingFilesAndHeadersAreErrorsNamingTheFile) {
  const std::string dir = ::testing::TempDir() + "/replay_missing";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/beacons.csv") << "beacon_id,x_m,y_m\n1,0,0\n";
  try {
    ReplaySource replay(dir);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("beacons.csv:1: header lacks column 'z_m'"), std::string::npos)
        << e.what();
  }
  std::ofstream(dir + "/beacons.csv") << "beacon_id,x_m,y_m,z_m\n1,0,0,0\n";
  try {
    ReplaySource replay(dir);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("odom.csv"), std::string::npos) << e.what();
  }
}

TEST(Replay, SharedRecordingsLoad) {
  const std::vector<std::pair<std::string, std::size_t>> recordings = {
      {"tuc_labyrinth_uwb/replay/full_933s", 7273}, {"cmu_plaza_gpslam/replay/plaza1", 3529}};
  int loaded = 0;
  for (const auto& [dir, ranges] : recordings) {
    const std::string path = kShared + "/" + dir;
    if (!std::filesystem::exists(path)) {
      std::printf("skipped %s: the shared datasets are not beside the repository (%s)\n", dir.c_str(),
                  path.c_str());
      continue;
    }
    ++loaded;
    ReplaySource replay(path);
    EXPECT_EQ(replay.load_counts().rejected_total(), 0u) << dir;
    std::size_t tofs = 0;
    for (const auto& e : everything(replay)) tofs += e.kind == SourceEvent::Kind::kTof;
    EXPECT_EQ(tofs, ranges) << dir;
  }
  if (loaded == 0) GTEST_SKIP() << "no shared dataset beside the repository";
}

}  // namespace
}  // namespace beaconloc
