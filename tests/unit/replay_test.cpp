// The replay source: the fixture and the shared recordings load; rows become the bus's samples
// exactly; bad rows are refused and counted with their file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

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

// Beacons without a radio message (seed 002): pulses.csv instead of ranges.csv, each row a pulse
// arrival with its double-burst mark; a mark that is none of the three is refused by name.
TEST(Replay, PulseArrivalsReplayWithTheirMarkAndABadMarkIsRefused) {
  const std::string dir = ::testing::TempDir() + "/replay_pulses";
  std::filesystem::remove_all(dir);  // a previous run's files
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/beacons.csv") << "beacon_id,x_m,y_m,z_m\n1,1,2,3\n2,4,2,3\n";
  std::ofstream(dir + "/odom.csv") << "t_s,dt_s,v_mps,omega_radps\n10.0,0.2,0.8,0.1\n";
  std::ofstream(dir + "/pulses.csv") << "t_s,mark\n10.05,double\n10.2,single\n10.35,not_reported\n10.5,triple\n";
  ReplaySource replay(dir);
  EXPECT_EQ(replay.beacon_input(), BeaconInput::kPulseArrivals);
  std::vector<PulseMark> marks;
  for (const auto& e : everything(replay)) {
    if (e.kind != SourceEvent::Kind::kPulse) continue;
    EXPECT_EQ(e.pulse.stamp_ns, e.stamp_ns);
    EXPECT_EQ(e.pulse.receiver_id, 0u);
    marks.push_back(e.pulse.mark);
  }
  EXPECT_EQ(marks, (std::vector<PulseMark>{PulseMark::kDouble, PulseMark::kSingle, PulseMark::kNotReported}));
  EXPECT_EQ(replay.load_counts().rejected("pulses.invalid_mark"), 1u);
  // One way of hearing the beacons per recording.
  std::ofstream(dir + "/ranges.csv") << "t_s,beacon_id,range_m\n10.1,1,2.5\n";
  EXPECT_THROW(ReplaySource{dir}, ReplayError);
  // A recording of ranges is what it always was.
  std::filesystem::remove(dir + "/pulses.csv");
  EXPECT_EQ(ReplaySource(dir).beacon_input(), BeaconInput::kRawTof);
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
  EXPECT_EQ(c.rejected("odom.invalid_dt_s"), 1u);
  EXPECT_EQ(c.rejected("ranges.malformed_row"), 2u);
  EXPECT_EQ(c.rejected("gt.duplicate_row"), 1u);
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

// Writes a recording of the given files (beacons.csv and odom.csv default to one good row).
std::string recording(const std::string& name, const std::map<std::string, std::string>& files) {
  const std::string dir = ::testing::TempDir() + "/" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::map<std::string, std::string> all = {{"beacons.csv", "beacon_id,x_m,y_m,z_m\n1,0,0,0\n"},
                                            {"odom.csv", "t_s,dt_s,v_mps,omega_radps\n1.0,0.1,0.5,0\n"},
                                            {"ranges.csv", "t_s,beacon_id,range_m\n"}};
  for (const auto& [file, text] : files) all[file] = text;
  for (const auto& [file, text] : all) std::ofstream(dir + "/" + file) << text;
  return dir;
}

bool has_problem(const ReplaySource& r, const std::string& text) {
  for (const auto& p : r.load_problems()) {
    if (p.find(text) != std::string::npos) return true;
  }
  return false;
}

// Every number of a recording is a decimal number within its column's range: refused rows are
// counted by file and column, and reported with the file, line, column and cell.
TEST(Replay, EveryNumberIsRangeCheckedWithAReasonNamingItsColumn) {
  const std::string dir =
      recording("replay_numbers",
                {{"odom.csv",
                  "t_s,dt_s,v_mps,omega_radps,half_track_m\n"
                  "1.0,0.1,0.5,0,0.2\n"
                  "1.1,0.1,1e300,0,0.2\n"  // line 3: an absurd speed
                  "1.2,0.1,10.5,0,0.2\n"   // line 4: beyond kMaxWheelSpeedMps
                  "1.3,0.1,9,10,0.2\n"     // line 5: v fine, but a wheel turns at 11 m/s
                  "1.4,0.1,0x1p1,0,0.2\n"  // line 6: hexadecimal
                  "-1,0.1,0.5,0,0.2\n"     // line 7: a negative stamp
                  "1.5,0.1,0.5,0,6\n"      // line 8: a 12 m wheel base
                  "1.6,0.1, 0.5,0,0.2\n"   // line 9: a space before the number
                  "1.7,0.1,0.5,inf,0.2\n"  // line 10: not a decimal number
                  "1.8,5000,0.5,0,0.2\n"   // line 11: an interval of over an hour
                  "1.9,0.1,0.5,0,0.2\n"},
                 {"ranges.csv",
                  "t_s,beacon_id,range_m\n1.0,1,3.0\n1.1,1,1e400\n1.2,1,20000\n1.3,0x1,3.0\n1.4,010,3.0\n"
                  "1e10,1,3.0\n"},
                 {"gt.csv", "t_s,x_m,y_m,yaw_rad\n1.0,0,0,0\n1.1,2e6,0,0\n1.2,0,0,1e7\n1.3,nan,0,0\n"}});
  ReplaySource replay(dir);
  const auto& c = replay.load_counts();
  EXPECT_EQ(c.rejected("odom.invalid_v_mps"), 2u);
  EXPECT_EQ(c.rejected("odom.invalid_omega_radps"), 1u);
  EXPECT_EQ(c.rejected("odom.malformed_row"), 3u);  // 0x1p1, " 0.5", inf
  EXPECT_EQ(c.rejected("odom.invalid_t_s"), 1u);
  EXPECT_EQ(c.rejected("odom.invalid_half_track_m"), 1u);
  EXPECT_EQ(c.rejected("odom.invalid_dt_s"), 1u);
  EXPECT_EQ(c.rejected("ranges.invalid_range_m"), 2u);  // 1e400 (beyond a double), 20 km
  EXPECT_EQ(c.rejected("ranges.malformed_row"), 1u);    // 0x1: an id is decimal ("010" is 10)
  EXPECT_EQ(c.rejected("ranges.invalid_t_s"), 1u);      // 1e10 s: beyond kMaxFileStampS
  EXPECT_EQ(c.rejected("gt.invalid_x_m"), 1u);
  EXPECT_EQ(c.rejected("gt.invalid_yaw_rad"), 1u);
  EXPECT_EQ(c.rejected("gt.malformed_row"), 1u);
  EXPECT_TRUE(has_problem(replay, "odom.csv:3: v_mps 1e+300 is outside [-10, 10]"));
  EXPECT_TRUE(
      has_problem(replay, "odom.csv:5: omega_radps 10 turns the wheels at 11 and 7 m/s, beyond 10 m/s"));
  EXPECT_TRUE(has_problem(replay, "odom.csv:6: v_mps '0x1p1' is not a decimal number"));
  EXPECT_TRUE(has_problem(replay, "odom.csv:7: t_s -1 is outside [0, 4.6e+09]"));
  EXPECT_TRUE(has_problem(replay, "odom.csv:9: v_mps ' 0.5' is not a decimal number"));
  EXPECT_TRUE(has_problem(replay, "ranges.csv:3: range_m '1e400' is out of range"));
  EXPECT_TRUE(has_problem(replay, "ranges.csv:5: beacon_id '0x1' is not a decimal number"));
  std::size_t odometry = 0, tofs = 0;
  for (const auto& e : everything(replay)) {
    odometry += e.kind == SourceEvent::Kind::kOdometry;
    tofs += e.kind == SourceEvent::Kind::kTof;
    if (e.kind == SourceEvent::Kind::kTof) {
      EXPECT_TRUE(e.tof.beacon_id == 1 || e.tof.beacon_id == 10);
    }
  }
  EXPECT_EQ(odometry, 2u);  // lines 2 and 12
  EXPECT_EQ(tofs, 2u);      // 3.0 m to beacon 1, and to beacon 10 (decimal)
}

// A range, odometry interval or truth row given twice is refused as a duplicate, counted and
// named with the row it repeats; the first is replayed (a duplicated ranges row was fused twice).
TEST(Replay, DuplicateRowsAreRefusedNamingTheRowTheyRepeat) {
  const std::string dir = recording(
      "replay_duplicates",
      {{"odom.csv",
        "t_s,dt_s,v_mps,omega_radps\n1.0,0.1,0.5,0\n1.0,0.1,0.5,0\n1.1,0.1,0.5,0\n1.1995,0.0005,0.5,0\n"},
       {"ranges.csv", "t_s,beacon_id,range_m\n1.0,1,3.0\n1.0,1,3.0\n1.0,2,4.0\n1.0,1,3.5\n0.5,1,2.0\n"},
       {"beacons.csv", "beacon_id,x_m,y_m,z_m\n1,0,0,0\n2,1,0,0\n"},
       {"gt.csv", "t_s,x_m,y_m\n1.0,0,0\n1.0,0,0\n1.1,0,0\n"}});
  ReplaySource replay(dir);
  const auto& c = replay.load_counts();
  EXPECT_EQ(c.rejected("ranges.duplicate_row"), 2u);  // the exact copy, and the other value
  EXPECT_EQ(c.rejected("odom.duplicate_row"), 2u);    // the same interval; one ending at the same stamp
  EXPECT_EQ(c.rejected("gt.duplicate_row"), 1u);
  EXPECT_EQ(c.rejected_total(), 5u);
  EXPECT_TRUE(has_problem(replay, "ranges.csv:3: a second range to beacon 1 at t_s 1.0 (first at line 2)"));
  EXPECT_TRUE(has_problem(replay, "ranges.csv:5: a second range to beacon 1 at t_s 1.0 (first at line 2)"));
  EXPECT_TRUE(has_problem(replay, "odom.csv:3: the same interval as line 2"));
  EXPECT_TRUE(has_problem(replay, "odom.csv:5: an interval ending at the same stamp as line 4"));
  EXPECT_TRUE(has_problem(replay, "gt.csv:3: the same t_s as line 2"));
  std::vector<double> ranges;
  std::size_t odometry = 0;
  for (const auto& e : everything(replay)) {
    if (e.kind == SourceEvent::Kind::kTof) ranges.push_back(e.tof.tof_s);
    odometry += e.kind == SourceEvent::Kind::kOdometry;
  }
  EXPECT_EQ(ranges.size(), 3u);  // 2.0 m at 0.5 s, 3.0 m to beacon 1 and 4.0 m to beacon 2 at 1.0 s
  EXPECT_EQ(odometry, 2u);
}

// A UTF-8 byte order mark before the header (a spreadsheet's "CSV UTF-8") is an encoding mark:
// the first column is found by its name. A header that names a column twice is an error.
TEST(Replay, AByteOrderMarkIsAnEncodingMarkAndAColumnNamedTwiceIsAnError) {
  const std::string bom = "\xEF\xBB\xBF";
  const std::string dir =
      recording("replay_bom", {{"beacons.csv", bom + "beacon_id,x_m,y_m,z_m\n1,0,0,0\n"},
                               {"odom.csv", bom + "t_s,dt_s,v_mps,omega_radps\n1.0,0.1,0.5,0\n"},
                               {"ranges.csv", bom + "t_s,beacon_id,range_m\n1.0,1,3.0\n"},
                               {"gt.csv", bom + "t_s,x_m,y_m\n1.0,0,0\n"}});
  ReplaySource replay(dir);
  EXPECT_EQ(replay.load_counts().rejected_total(), 0u);
  EXPECT_EQ(replay.event_count(), 3u);
  const std::string twice =
      recording("replay_twice", {{"ranges.csv", "t_s,beacon_id,range_m,t_s\n1.0,1,3.0,2.0\n"}});
  try {
    ReplaySource r(twice);
    FAIL() << "a header naming t_s twice loaded";
  } catch (const ReplayError& e) {
    EXPECT_NE(std::string(e.what()).find("ranges.csv:1: header names column 't_s' twice"), std::string::npos)
        << e.what();
  }
}

// The noise reported with a row: a recording without wheels has it on (v, omega), mapped onto
// the wheel speeds so that it comes back the same for any wheel base (the filters' eq. 16 map:
// v = (v_R + v_L) / 2, omega = (v_R - v_L) / B); one with the robot's wheels has it per wheel.
TEST(Replay, OdometryNoiseIsTheSensorsWhateverWheelBaseExpressesIt) {
  const std::string without_wheels =
      recording("replay_noise_v_omega", {{"odom.csv", "t_s,dt_s,v_mps,omega_radps\n1.0,0.2,0.8,0.3\n"}});
  for (const double wheel_base_m : {0.3, 0.5, 4.0}) {
    ReplayOptions options;
    options.wheel_base_m = wheel_base_m;
    options.odometry_k_v_m = 0.002;
    options.odometry_heading_arw_rad_per_sqrt_s = 0.01;
    ReplaySource replay(without_wheels, options);
    const auto events = everything(replay);
    ASSERT_EQ(events.size(), 1u);
    const OdometrySample& o = events[0].odometry;
    Eigen::Matrix2d to_v_omega;  // [v, omega] = T [v_R, v_L]
    to_v_omega << 0.5, 0.5, 1.0 / o.wheel_base_m, -1.0 / o.wheel_base_m;
    const Eigen::Matrix2d c = to_v_omega * o.wheel_velocity_covariance * to_v_omega.transpose();
    EXPECT_NEAR(c(0, 0), 0.002 * 0.8 / 0.2, 1e-15) << "B " << wheel_base_m;
    EXPECT_NEAR(c(1, 1), 0.01 * 0.01 / 0.2, 1e-15) << "B " << wheel_base_m;
    EXPECT_NEAR(c(0, 1), 0.0, 1e-15) << "B " << wheel_base_m;
    EXPECT_EQ(o.wheel_velocity_covariance(0, 1), o.wheel_velocity_covariance(1, 0));  // exactly symmetric
  }
  for (const double bad : {-1e-3, 2.0, std::nan("")}) {
    ReplayOptions options;
    options.odometry_heading_arw_rad_per_sqrt_s = bad;
    EXPECT_THROW(ReplaySource(without_wheels, options), ReplayError) << bad;
    options = ReplayOptions();
    options.odometry_k_v_m = bad;
    EXPECT_THROW(ReplaySource(without_wheels, options), ReplayError) << bad;
  }
  const std::string with_wheels = recording(
      "replay_noise_wheels", {{"odom.csv", "t_s,dt_s,v_mps,omega_radps,half_track_m\n1.0,0.2,0.8,0.3,0.1\n"}});
  ReplayOptions options;
  options.odometry_k_v_m = 0.002;
  ReplaySource replay(with_wheels, options);
  const OdometrySample o = everything(replay)[0].odometry;
  EXPECT_DOUBLE_EQ(o.wheel_velocity_covariance(0, 0), 0.002 * (0.8 + 0.3 * 0.1) / 0.2);
  EXPECT_DOUBLE_EQ(o.wheel_velocity_covariance(1, 1), 0.002 * (0.8 - 0.3 * 0.1) / 0.2);
  EXPECT_EQ(o.wheel_velocity_covariance(0, 1), 0.0);
}

TEST(Replay, SharedRecordingsLoad) {
  // Plaza 1 files two ranges twice (lines 2868 and 2892 repeat the stamp and beacon of lines 2767
  // and 2791, in a block filed 64 s late, with other values): the second of each is refused.
  struct Recording {
    std::string dir;
    std::size_t ranges;
    std::uint64_t duplicates;
  };
  const std::vector<Recording> recordings = {{"tuc_labyrinth_uwb/replay/full_933s", 7273, 0},
                                             {"cmu_plaza_gpslam/replay/plaza1", 3529 - 2, 2}};
  int loaded = 0;
  for (const auto& [dir, ranges, duplicates] : recordings) {
    const std::string path = kShared + "/" + dir;
    if (!std::filesystem::exists(path)) {
      std::printf("skipped %s: the shared datasets are not beside the repository (%s)\n", dir.c_str(),
                  path.c_str());
      continue;
    }
    ++loaded;
    ReplaySource replay(path);
    EXPECT_EQ(replay.load_counts().rejected_total(), duplicates) << dir;
    EXPECT_EQ(replay.load_counts().rejected("ranges.duplicate_row"), duplicates) << dir;
    std::size_t tofs = 0;
    for (const auto& e : everything(replay)) tofs += e.kind == SourceEvent::Kind::kTof;
    EXPECT_EQ(tofs, ranges) << dir;
  }
  if (loaded == 0) GTEST_SKIP() << "no shared dataset beside the repository";
}

}  // namespace
}  // namespace beaconloc
