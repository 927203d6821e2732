// Seed 003's globally and locally referenced beacons (issue 16, item 4): the map holds both, the
// estimators find only beacons with a map position (a range to a locally referenced one is
// uncalibrated_beacon, counted), and a scenario, a recording's beacons.csv and the wire say which
// beacon is which.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "offline_run.hpp"
#include "sim/scenario_yaml.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {
namespace {

BeaconList two_kinds() {
  return {{{11, {1.0, 2.0, 3.0}, 1}, {12, {2.0, 2.0, 3.0}, 1}}, {{31, 3, {0.35, -0.35, 3.0}}, {32, 3, {-0.35, 0.35, 3.0}}}};
}

TEST(BeaconReferencing, TheMapFindsOnlyBeaconsWithAMapPosition) {
  const BeaconMap map(two_kinds());
  EXPECT_EQ(map.size(), 2u);
  EXPECT_EQ(map.local_size(), 2u);
  EXPECT_TRUE(map.find(11));
  EXPECT_FALSE(map.find(31));  // never as if its map position were known
  ASSERT_TRUE(map.find_local(31));
  EXPECT_EQ(map.find_local(31)->group, 3u);
  EXPECT_FALSE(map.find_local(11));
  EXPECT_FALSE(map.empty());
  EXPECT_EQ(BeaconMap(map.list()), map);
  // The same beacon in the map frame is another map.
  BeaconList moved = two_kinds();
  moved.group_frame.pop_back();
  moved.map_frame.push_back({32, {-0.35, 0.35, 3.0}, 4});
  EXPECT_NE(BeaconMap(moved), map);
  BeaconList shifted = two_kinds();  // only a local beacon's position differs
  shifted.group_frame[1].position_group_m.x() += 0.01;
  EXPECT_NE(BeaconMap(shifted), map);
  BeaconList regrouped = two_kinds();  // only a local beacon's group differs
  regrouped.group_frame[1].group = 4;
  EXPECT_NE(BeaconMap(regrouped), map);
}

TEST(BeaconReferencing, AMapMixingTheKindsWronglyIsRefusedWithTheReason) {
  BeaconList no_group = two_kinds();
  no_group.group_frame[0].group = 0;
  EXPECT_EQ(check_beacons(no_group).problem, BeaconMapProblem::kLocalWithoutGroup);
  BeaconList both = two_kinds();
  both.group_frame[0].group = 1;
  EXPECT_EQ(check_beacons(both).problem, BeaconMapProblem::kGroupBothKinds);
  EXPECT_EQ(check_beacons(both).beacon_id, 31u);
  BeaconList twice = two_kinds();
  twice.group_frame[0].id = 11;
  EXPECT_EQ(check_beacons(twice).problem, BeaconMapProblem::kDuplicateId);
  BeaconList nan = two_kinds();
  nan.group_frame[1].position_group_m.x() = std::nan("");
  EXPECT_EQ(check_beacons(nan).problem, BeaconMapProblem::kNonFinitePosition);
  RejectionCounter counts;
  EXPECT_FALSE(counted_beacon_map(both, counts));
  EXPECT_EQ(counts.rejected("beacon_map.group_both_kinds"), 1u);
  EXPECT_TRUE(BeaconMap::from({{}, {{31, 3, {0.0, 0.0, 3.0}}}}, nullptr));  // local beacons only: a map
}

TEST(BeaconReferencing, ARangeToAnUncalibratedBeaconIsRefusedAsSuchAndTheDecoderStillDecodesIt) {
  const BeaconMap map(two_kinds());
  RangeMeasurement r;
  r.stamp_ns = 1'000'000'000;
  r.range_m = 3.2;
  r.variance_m2 = 1e-4;
  r.beacon_id = 31;
  EXPECT_EQ(check_range(r, map, 1).rejection, Rejection::kUncalibratedBeacon);
  r.beacon_id = 77;
  EXPECT_EQ(check_range(r, map, 1).rejection, Rejection::kUnknownBeacon);
  r.beacon_id = 11;
  EXPECT_TRUE(check_range(r, map, 1).accepted);
  // The decoder turns the locally referenced beacon's TOF into a range: a calibration needs it.
  TofDecoder decoder;
  decoder.set_beacon_map(map);
  RawTofSample tof;
  tof.beacon_id = 31;
  tof.fire_stamp_ns = 1'000'000'000;
  tof.tof_s = 0.009;
  tof.beacon_temperature_c = 20.0;
  EXPECT_TRUE(decoder.decode("r", tof).range);
  tof.beacon_id = 77;
  tof.sequence_number = 1;
  EXPECT_FALSE(decoder.decode("r", tof).range);
  EXPECT_EQ(decoder.counts().rejected("unknown_beacon"), 1u);
}

sim::Scenario seed003() {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed003_scan.yaml");
}

// The scenario keeps every beacon's true map position; what it publishes puts the LRULPSs' beacons
// in their own frames, from which the frames' true poses give the truth back.
TEST(BeaconReferencing, Seed003PublishesItsLocalGroupsInTheirOwnFrames) {
  const sim::Scenario s = seed003();
  ASSERT_EQ(s.local_group_frames_map.size(), 7u);
  const BeaconList list = s.beacon_list();
  EXPECT_EQ(list.map_frame.size(), 10u);    // GRULPS 1 and 2, five beacons each
  EXPECT_EQ(list.group_frame.size(), 28u);  // LRULPS #1-#7, four each
  const BeaconMap truth(s.beacons);
  for (const LocalBeacon& b : list.group_frame) {
    const Pose2& frame = s.local_group_frames_map.at(b.group);
    const Eigen::Vector2d back = transform_point(frame, b.position_group_m.head<2>());
    EXPECT_TRUE(back.isApprox(truth.find(b.id)->position_map_m.head<2>(), 1e-9)) << b.id;
    EXPECT_LT(b.position_group_m.head<2>().norm(), 0.51) << b.id;  // a corner of a 1 m-diagonal square
  }
  // The 30 deg frame of group 4: its first beacon is not where the map axes would put it.
  const BeaconMap published(list);
  const LocalBeacon* b41 = published.find_local(41);
  ASSERT_TRUE(b41);
  EXPECT_GT((b41->position_group_m.head<2>() - Eigen::Vector2d(0.3535533906, 0.3535533906)).norm(), 0.1);
}

// On seed 003 every estimator that takes ranges and does not calibrate refuses each range to an
// LRULPS beacon, as uncalibrated (or, in a mode that uses no beacon, as unused), counted. `scan`
// calibrates: its LRULPS ranges go to the group's own frame only (ScanEstimator.*).
TEST(BeaconReferencing, OnSeed003NoEstimatorUsesAnUncalibratedBeacon) {
  const sim::Scenario s = seed003();
  std::uint64_t local_tofs = 0;
  const BeaconMap truth(s.beacons);
  for (const SourceEvent& e : simulate(s, 1, s.duration_s)) {
    if (e.kind != SourceEvent::Kind::kTof) continue;
    local_tofs += s.local_group_frames_map.count(truth.find(e.true_beacon_id)->group);
  }
  EXPECT_GT(local_tofs, 500u);
  int checked = 0;
  for (const std::string& name : EstimatorRegistry::instance().names()) {
    SCOPED_TRACE(name);
    if (EstimatorRegistry::instance().reference_scenario(name).empty()) continue;  // a test double, not the product's
    if (name == "scan") continue;  // the one that calibrates
    EstimatorConfig config;
    config.receivers = s.receivers;
    std::unique_ptr<Estimator> probe;
    try {
      probe = EstimatorRegistry::instance().create(name, config);
    } catch (const std::invalid_argument&) {
      continue;  // not for this robot (duhl needs its three receivers)
    }
    if (probe->beacon_input() != BeaconInput::kRanges) continue;
    const OfflineRunResult r = run_scenario_offline(s, 1, name, {});
    // Every one of them, but those the decoder refused first (a TOF past the range limit by its noise).
    const std::uint64_t refused = r.rejections.rejected("localizer.range.uncalibrated_beacon") +
                                  r.rejections.rejected("localizer.range.beacons_unused");
    EXPECT_GE(refused, local_tofs - r.rejections.rejected("decoder.out_of_range_tof"));
    EXPECT_EQ(r.rejections.rejected("decoder.unknown_beacon"), 0u);
    EXPECT_EQ(r.rejections.rejected("localizer.range.unknown_beacon"), 0u);
    ++checked;
  }
  EXPECT_GE(checked, 2);  // range_ekf, ukf_lrf_beacons_only (duhl and uhl_last2 need three receivers, ukf_lrf a laser)
}

// Seed 002's estimator cannot model beacons whose positions it does not know firing in its
// cycle: a map with any is refused with the reason, not half used.
TEST(BeaconReferencing, KleemanRefusesAMapWithLocallyReferencedBeacons) {
  EstimatorConfig config;
  config.receivers.receivers_base_m.push_back(Eigen::Vector2d::Zero());
  auto k = EstimatorRegistry::instance().create("kleeman_iekf", config);
  k->set_beacon_map(BeaconMap(BeaconList({{1, {0, 0, 3}, 1}, {2, {5, 0, 3}, 1}, {3, {0, 5, 3}, 1}},
                                         {{41, 4, {0.3, 0.3, 3.0}}})));
  PulseArrivalSample p;
  p.stamp_ns = 1'000'000'000;
  p.mark = PulseMark::kDouble;
  const InputResult r = k->update_pulse(p);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.rejection, Rejection::kBeaconMapUnusable);
}

std::string scenario_error(const std::string& groups) {
  const std::string yaml = "name: t\nbeacons:\n  - {id: 1, position_m: [0, 0, 2], group: 1}\n"
                           "  - {id: 2, position_m: [1, 0, 2], group: 2}\n" + groups +
                           "robot:\n  receivers: {positions_m: [[0, 0]]}\n"
                           "trajectory:\n  waypoints_m: [[0, 0], [1, 0]]\n  speed_mps: 0.5\n";
  try {
    sim::parse_scenario(yaml, "t.yaml");
  } catch (const sim::ScenarioError& e) {
    return e.what();
  }
  return "";
}

TEST(BeaconReferencing, AScenarioSaysWhichGroupsAreLocalOrGetsAnErrorNamingTheKey) {
  EXPECT_EQ(scenario_error("groups:\n  - {id: 2, referenced: local, frame_pose_m: [1, 0, 90]}\n"), "");
  EXPECT_NE(scenario_error("groups:\n  - {id: 2, referenced: local}\n").find("'groups[0].frame_pose_m' is required"),
            std::string::npos);
  EXPECT_NE(scenario_error("groups:\n  - {id: 1, referenced: global, frame_pose_m: [0, 0, 0]}\n")
                .find("locally referenced group only"),
            std::string::npos);
  EXPECT_NE(scenario_error("groups:\n  - {id: 5, referenced: global}\n").find("not the group of any beacon"),
            std::string::npos);
  EXPECT_NE(scenario_error("groups:\n  - {id: 0, referenced: global}\n").find("is 0"), std::string::npos);
  EXPECT_NE(scenario_error("groups:\n  - {id: 2, referenced: maybe}\n").find("must be global or local"),
            std::string::npos);
  EXPECT_NE(scenario_error("groups:\n  - {id: 2, referenced: global}\n  - {id: 2, referenced: global}\n")
                .find("repeats an earlier group"),
            std::string::npos);
}

TEST(BeaconReferencing, BeaconsCsvSaysEachBeaconsFrameAndRefusesWhatItCannotMean) {
  const std::string dir = ::testing::TempDir() + "/beacon_referencing";
  std::filesystem::create_directories(dir);
  const BeaconMap map(two_kinds());
  write_beacon_map_csv(dir + "/beacons.csv", map);
  EXPECT_EQ(load_beacon_map_csv(dir + "/beacons.csv"), map);
  const auto error = [&](const std::string& rows) {
    std::ofstream(dir + "/bad.csv") << "beacon_id,x_m,y_m,z_m,group,frame\n" << rows;
    try {
      load_beacon_map_csv(dir + "/bad.csv");
    } catch (const CsvError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("1,0,0,3,0,group\n").find("bad.csv: beacon 1: local_without_group"), std::string::npos);
  EXPECT_NE(error("1,0,0,3,1,grop\n").find("frame 'grop' is neither map nor group"), std::string::npos);
  EXPECT_NE(error("1,0,0,3,1,map\n2,0,0,3,1,group\n").find("beacon 2: group_both_kinds"), std::string::npos);
  // A file without the columns is the map frame, group 0, as before.
  std::ofstream(dir + "/old.csv") << "beacon_id,x_m,y_m,z_m\n1,0,0,3\n";
  const BeaconMap old = load_beacon_map_csv(dir + "/old.csv");
  ASSERT_TRUE(old.find(1));
  EXPECT_EQ(old.find(1)->group, 0u);
}

}  // namespace
}  // namespace beaconloc
