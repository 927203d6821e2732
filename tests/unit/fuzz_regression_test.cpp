// Inputs the fuzz targets (tests/fuzz, docs/fuzzing.md) found, each now refused with its typed
// error or counted rejection: none may crash, overflow, escape as another exception type or be
// silently repaired.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/occupancy_grid_io.hpp"
#include "evaluation.hpp"
#include "replay/replay_source.hpp"
#include "sim/scenario_yaml.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {
namespace {

constexpr StampNs kMaxStamp = std::numeric_limits<StampNs>::max();
constexpr StampNs kMinStamp = std::numeric_limits<StampNs>::min();

std::string scenario_error(const std::string& yaml) {
  try {
    sim::parse_scenario(yaml, "fuzz.yaml");
  } catch (const sim::ScenarioError& e) {
    return e.what();
  }
  return "";
}

// fuzz_scenario_yaml: a mapping key that is itself a sequence (or null) escaped as
// YAML::TypedBadConversion from the check for unknown keys.
TEST(FuzzRegression, ScenarioKeyThatIsNotANameIsAScenarioError) {
  const std::string found =
      "name: t\nbeacons:\n? - {id: 0, pom: [[0, 0]]}\ntrajectory:\n  waypoints_m: [[1, 0], [~, 0]]\n"
      "  speed_mps: 0.6\n";
  EXPECT_EQ(scenario_error(found), "fuzz.yaml:3: 'the document' has a key that is not a name");
  EXPECT_EQ(scenario_error("? [a, b]\n: 1\nname: t\n"),
            "fuzz.yaml:1: 'the document' has a key that is not a name");
  EXPECT_EQ(scenario_error("name: t\n~: 1\n"), "fuzz.yaml:2: 'the document' has a key that is not a name");
}

// fuzz_map_yaml (with -malloc_limit_mb=256): a text PGM's header alone allocated 4 bytes per
// claimed cell (400 MB for "P2 10000 10000 255") before reading any pixel. Now refused as
// truncated, allocating no more than its data.
TEST(FuzzRegression, TextPgmHeaderAloneAllocatesNothingAndIsRefused) {
  const std::string yaml = "image: m.pgm\nresolution: 1\norigin: [0, 0, 0]\n";
  try {
    parse_occupancy_grid(yaml, "P2 10000 10000 255 0", "m.yaml", "m.pgm");
    FAIL() << "a PGM without its pixels loaded";
  } catch (const MapFileError& e) {
    EXPECT_EQ(std::string(e.what()), "m.pgm: bad or truncated PGM data");
  }
  // The same loader from memory as from files: a small text PGM loads.
  const OccupancyGrid grid = parse_occupancy_grid(yaml, "P2\n3 2\n255\n0 254 254\n254 254 0\n");
  EXPECT_EQ(grid.width(), 3);
  EXPECT_TRUE(grid.occupied(0, 1));
  EXPECT_TRUE(grid.occupied(2, 0));
  EXPECT_FALSE(grid.occupied(1, 0));
}

const std::string kMinimalScenario =
    "name: t\nbeacons:\n  - {id: 1, position_m: [0, 0, 2]}\nrobot:\n  receivers: {positions_m: [[0, 0]]}\n";

// fuzz_scenario_yaml: a map narrower than a cell (size_m 1e-12 m) escaped as std::invalid_argument
// from OccupancyGrid's constructor.
TEST(FuzzRegression, ScenarioMapNarrowerThanACellIsAScenarioError) {
  const std::string found = kMinimalScenario +
                            "trajectory:\n  waypoints_m: [[0, 0], [1, 0]]\n  speed_mps: 0.5\nmap:\n"
                            "  size_m: [1e-12, 1]\n";
  EXPECT_EQ(scenario_error(found), "fuzz.yaml:10: 'map.size_m' must be at least one cell a side");
}

// fuzz_scenario_yaml: a 700-byte scenario with a 20000 x 20000 map and a dozen obstacles took
// 400 MB (twice, with unmapped obstacles) and over 100 s to load: each rectangle visited every
// cell. Rectangles now fill only their rows, and a map holds at most 1e8 cells.
TEST(FuzzRegression, ScenarioMapOfMoreThan1e8CellsIsAScenarioError) {
  const std::string trajectory = "trajectory:\n  waypoints_m: [[0, 0], [1, 0]]\n  speed_mps: 0.5\n";
  EXPECT_EQ(
      scenario_error(kMinimalScenario + trajectory + "map:\n  resolution_m: 0.005\n  size_m: [100, 100]\n"),
      "fuzz.yaml:11: 'map.size_m' must be positive and at most 20000 cells a side, 100000000 cells in all");
  std::string obstacles;
  for (int i = 0; i < 12; ++i)
    obstacles += "    - {min_m: [" + std::to_string(i) + ", 0], max_m: [50, 49]}\n";
  const sim::Scenario s =
      sim::parse_scenario(kMinimalScenario + trajectory +
                              "map:\n  resolution_m: 0.01\n  size_m: [50, 50]\n  obstacles:\n" + obstacles,
                          "fuzz.yaml");
  ASSERT_TRUE(s.map.has_value());
  EXPECT_TRUE(s.map->occupied(1000, 2500));
  EXPECT_FALSE(s.map->occupied(1000, 4950));
}

// fuzz_scenario_yaml's property (the path is defined over the run): a loop of 1 us segments over
// 1e6 s made the simulator's pose_at count 5e11 laps in an int (undefined behaviour) and compose
// them one by one (a hang). Such a loop is now refused.
TEST(FuzzRegression, ScenarioLoopRepeatingMoreThan1e6TimesIsAScenarioError) {
  const std::string found =
      "name: t\nduration_s: 1000000\nbeacons:\n  - {id: 1, position_m: [0, 0, 2]}\n"
      "robot:\n  receivers: {positions_m: [[0, 0]]}\ntrajectory:\n  start_pose: [0, 0, 0]\n"
      "  loop: true\n  segments:\n    - {duration_s: 0.000001, linear_mps: 1}\n";
  EXPECT_EQ(scenario_error(found),
            "fuzz.yaml:9: 'trajectory.loop' would repeat the segments more than 1e6 times in duration_s");
}

RawTofSample tof_at(StampNs fire_ns, std::uint64_t seq) {
  RawTofSample s;
  s.beacon_id = 1;
  s.fire_stamp_ns = fire_ns;
  s.tof_s = 0.0073;
  s.beacon_temperature_c = 22.0;
  s.sequence_number = seq;
  return s;
}

const BeaconMap kMap({{1, {0.0, 0.0, 2.0}, 0}});

// fuzz_decoder_input: a firing stamp within a TOF of the end of the clock overflowed
// fire + TOF (the range's arrival stamp); now the typed rejection bad_stamp, counted.
TEST(FuzzRegression, DecoderRefusesAFiringWhoseArrivalOverflowsTheClock) {
  TofDecoder decoder;
  decoder.set_beacon_map(kMap);
  const DecodeOutcome out = decoder.decode("robot_0", tof_at(kMaxStamp - 13'427, 1));
  ASSERT_TRUE(out.rejection.has_value());
  EXPECT_EQ(*out.rejection, Rejection::kBadStamp);
  EXPECT_EQ(decoder.counts().rejected("bad_stamp"), 1u);
  EXPECT_EQ(decoder.counts().accepted(), 0u);
  // Just early enough, it decodes, and arrives exactly one TOF later.
  const DecodeOutcome ok = decoder.decode("robot_0", tof_at(kMaxStamp - 7'300'000, 2));
  ASSERT_TRUE(ok.range.has_value());
  EXPECT_EQ(ok.range->range.stamp_ns, kMaxStamp);
}

// fuzz_decoder_input: stamps near the start of the clock overflowed newest - max_age (stale
// check) and fire - max_age (the backlog before the map). Freshness is now judged without
// overflow: two firings 5 ns apart are both fresh, a firing from the far end is stale.
TEST(FuzzRegression, DecoderJudgesFreshnessAtTheEndsOfTheClock) {
  TofDecoder decoder;
  EXPECT_TRUE(decoder.decode("robot_0", tof_at(kMinStamp + 5, 1)).deferred);  // before the map
  EXPECT_TRUE(decoder.decode("robot_0", tof_at(kMinStamp + 10, 2)).deferred);
  EXPECT_EQ(decoder.set_beacon_map(kMap).size(), 2u);
  EXPECT_TRUE(decoder.decode("robot_0", tof_at(kMinStamp + 15, 3)).range.has_value());
  const DecodeOutcome far = decoder.decode("robot_1", tof_at(kMaxStamp - 1'000'000'000, 4));
  EXPECT_TRUE(far.range.has_value());
  // The whole clock behind the newest firing: far beyond max_jump_ns, a time jump to be confirmed.
  const DecodeOutcome stale = decoder.decode("robot_1", tof_at(kMinStamp + 20, 5));
  ASSERT_TRUE(stale.rejection.has_value());
  EXPECT_EQ(*stale.rejection, Rejection::kTimeJump);
  EXPECT_EQ(decoder.counts().accepted(), 4u);
  EXPECT_EQ(decoder.counts().rejected_total(), 1u);
}

// fuzz_replay_csv: a range of 5e14 m (a time of flight of 1.5e12 s, beyond the int64 ns clock)
// made s_to_ns return INT64_MIN and the firing stamp (arrival - TOF) overflow; a t_s as large
// overflowed the out-of-order note. Each such row is now refused, counted as invalid_<column>,
// and the rest of the recording loads.
TEST(FuzzRegression, ReplayRefusesTimesBeyondTheClock) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("beaconloc_fuzz_replay_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "beacons.csv") << "beacon_id,x_m,y_m,z_m\n1,0,0,0\n";
  std::ofstream(dir / "odom.csv") << "t_s,dt_s,v_mps,omega_radps\n1.0,0.1,0.5,0\n1e300,0.1,0.5,0\n"
                                     "4.6e9,1,0.5,0\n";
  std::ofstream(dir / "ranges.csv")
      << "t_s,beacon_id,range_m\n0.127943993,1,2.9\n-1e300,1,3.0\n1.0,159.,502522014829822\n"
         "1.0,159,502522014829822\n";
  std::ofstream(dir / "gt.csv") << "t_s,x_m,y_m\n1.0,0,0\n-9.3e9,0,0\n";
  ReplaySource replay(dir.string());
  const auto& c = replay.load_counts();
  EXPECT_EQ(c.rejected("odom.invalid_t_s"), 1u);   // 1e300
  EXPECT_EQ(c.rejected("odom.invalid_dt_s"), 1u);  // 4.6e9 + 1 s: its end
  EXPECT_EQ(c.rejected("ranges.invalid_t_s"), 1u);
  EXPECT_EQ(c.rejected("ranges.invalid_range_m"), 1u);  // 5e14 m, as found with beacon id 159
  EXPECT_EQ(c.rejected("ranges.malformed_row"), 1u);    // as found: the beacon id "159." is not whole
  EXPECT_EQ(c.rejected("gt.invalid_t_s"), 1u);
  EXPECT_EQ(replay.event_count(), 3u);  // one odometry, one range, one truth row
  EXPECT_TRUE(replay.load_notes().empty());
  std::filesystem::remove_all(dir);
}

// fuzz_eval_csv (an input written by hand while reviewing the target; the fuzzer had not reached
// it in 10 minutes): truth rows at both ends of the clock overflowed the gap between them in
// TruthTrack::at, and estimates as far apart overflowed error_series' time axis. The CSV files now
// refuse a negative stamp (no source clock has one); the evaluation still takes any two stamps.
TEST(FuzzRegression, EvaluationOfStampsAtBothEndsOfTheClockDoesNotOverflow) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("beaconloc_fuzz_eval_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "truth.csv") << "stamp_ns,x_m,y_m,yaw_rad\n-9000000000000000000,0,0,0\n";
  try {
    load_truth_csv((dir / "truth.csv").string());
    FAIL() << "a negative stamp loaded";
  } catch (const CsvError& e) {
    EXPECT_NE(std::string(e.what()).find("truth.csv:2: stamp_ns -9000000000000000000 is outside [0, "),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(dir);
  TruthTrack truth;
  truth.add(-9'000'000'000'000'000'000, {0, 0, 0}, true);
  truth.add(9'000'000'000'000'000'000, {1, 1, 0}, true);
  std::vector<EstimateRow> rows;
  for (const StampNs stamp :
       {StampNs{-9'000'000'000'000'000'000}, StampNs{0}, StampNs{9'000'000'000'000'000'000}}) {
    EstimateRow r;
    r.robot_id = "r";
    r.estimator = "e";
    r.estimate.stamp_ns = stamp;
    r.estimate.pose_map_base = stamp > 0 ? Pose2(1, 1, 0) : Pose2(0, 0, 0);
    r.estimate.status = PoseStatus::kOk;
    rows.push_back(r);
  }
  EXPECT_FALSE(truth.at(0, kMaxStamp).has_value());  // 1.8e19 ns between the rows: wider than any gap
  EvaluationOptions every_stamp;
  every_stamp.score_from_ns = kMinStamp;
  const Metrics m = evaluate(truth, rows, every_stamp);
  EXPECT_EQ(m.samples, 2u);
  EXPECT_EQ(m.samples_without_truth, 1u);  // at 0: 1.8e19 ns between truth rows
  const auto errors = error_series(truth, rows, every_stamp);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].t_s, 0.0);
  EXPECT_DOUBLE_EQ(errors[1].t_s, 1.8e10);
}

// fuzz_eval_csv (600 s run, issue 23): an estimate row whose covariance is not symmetric
// (cov_01 0.001, cov_10 0.1) loaded, and evaluate() then threw std::invalid_argument out of
// `beaconloc eval`; the loader refuses it as a CsvError naming the line, as every pose reader does.
TEST(FuzzRegression, EstimateCsvRefusesAPoseNoLocalizerPublishes) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("beaconloc_fuzz_estimate_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string header =
      "robot_id,stamp_ns,x_m,y_m,yaw_rad,cov_00,cov_01,cov_02,cov_10,cov_11,cov_12,cov_20,cov_21,cov_22,status,"
      "estimator\n";
  const std::string good = "robot_0,1050000000,0.51,0.49,0.1,0.01,0,0,0,0.01,0,0,0,0.02,ok,range_ekf\n";
  for (const std::string& bad : {std::string("robot_0,1150000000,0.55,0.5,0.13,1.01,0.001,0,000.1,0.01,0,0,0,0.02,"
                                             "degraded,range_ekf\n"),
                                 std::string("robot_0,1150000000,0.55,0.5,0.13,-1,0,0,0,0.01,0,0,0,0.02,ok,e\n"),
                                 std::string("robot_0,1150000000,0.55,0.5,0.13,1e300,0,0,0,0.01,0,0,0,0.02,ok,e\n")}) {
    std::ofstream(dir / "estimate.csv") << header << good << bad;
    try {
      load_estimates_csv((dir / "estimate.csv").string());
      FAIL() << "loaded: " << bad;
    } catch (const CsvError& e) {
      EXPECT_NE(std::string(e.what()).find("estimate.csv:3: not a pose a localizer publishes"), std::string::npos)
          << e.what();
    }
  }
  std::ofstream(dir / "estimate.csv") << header << good;
  EXPECT_EQ(load_estimates_csv((dir / "estimate.csv").string()).size(), 1u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace beaconloc
