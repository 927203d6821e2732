// The site's calibration in the localizer (LocalizerCore::on_calibration, issue 16 item 3): what
// one robot calibrates reaches every robot the localizer serves, a robot made later starts with
// it, a calibration received before the map is used once the map comes, a late measurement's
// replay does not roll it back, and one that does not fit the map is never used.
#include <gtest/gtest.h>

#include <string>

#include "localizer_core.hpp"
#include "offline_run.hpp"
#include "scan/scan_estimator.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc::scan {
namespace {

sim::Scenario seed003() {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed003_scan.yaml");
}

EstimatorConfig config_of(const sim::Scenario& s) {
  EstimatorConfig c;
  c.receivers = s.receivers;
  return c;
}

const ScanEstimator& scan_of(const LocalizerCore& core, const std::string& robot) {
  const auto* scan = dynamic_cast<const ScanEstimator*>(core.estimator(robot));
  if (!scan) throw std::logic_error("no scan estimator for " + robot);
  return *scan;
}

// Drives `robot` through the scenario (seed) for duration_s, as the participant feeds the core.
void drive(LocalizerCore& core, const sim::Scenario& s, const std::string& robot, std::uint64_t seed,
           double duration_s) {
  TofDecoder decoder = scenario_decoder(s);
  for (const SourceEvent& e : simulate(s, seed, duration_s)) {
    if (auto in = estimator_input(robot, e, decoder, BeaconInput::kRanges)) core.on_input(robot, std::move(*in));
  }
}

double calibrated_groups(const LocalizerCore& core, const std::string& robot) {
  for (const auto& v : core.estimator(robot)->state_values()) {
    if (v.name == "calibrated_groups") return v.value;
  }
  return -1.0;
}

// One robot calibrates; the site's calibration follows it group by group; a second robot, made
// afterwards, holds every group before it has moved.
TEST(ScanCalibrationSharing, WhatOneRobotCalibratesEveryRobotOfTheLocalizerUses) {
  const sim::Scenario s = seed003();
  LocalizerCore core("scan", config_of(s));
  core.set_beacon_map(BeaconMap(s.beacon_list()));
  // 10 s more than the path, standing in GRULPS 2: the backwards drive runs (inverse_after_s).
  drive(core, s, "first", 1, s.duration_s + 12.0);
  const BeaconCalibration& site = core.calibration();
  ASSERT_EQ(site.groups.size(), s.local_group_frames_map.size());
  EXPECT_TRUE(check_calibration(site).ok());
  // The robot's own, in the site's order (by group).
  BeaconCalibration own;
  merge_calibration(own, scan_of(core, "first").calibration());
  EXPECT_EQ(site, own);
  // Each group once, then again where the backwards drive found a better one: a handful of
  // changes, not one per sample.
  EXPECT_GE(core.calibration_revision(), site.groups.size());
  EXPECT_LE(core.calibration_revision(), 2 * site.groups.size());

  // A second robot: its estimator holds every group at its first sample.
  OdometrySample standing;
  standing.stamp_ns = 1;
  standing.wheel_base_m = 0.5;
  core.on_odometry("second", standing);
  EXPECT_EQ(calibrated_groups(core, "second"), static_cast<double>(site.groups.size()));
  EXPECT_EQ(scan_of(core, "second").calibration(), site);
  EXPECT_TRUE(core.calibration_groups_unfit().empty());
}

// A calibration from the bus or a file may come before the beacon map: kept, and given to the
// robots once the map is there. A second localizer's robot drives with no calibration drive of
// its own: it calibrates nothing, and a late range (replayed from a copy of its estimator made
// before) leaves it holding every group.
TEST(ScanCalibrationSharing, ACalibrationReceivedBeforeTheMapIsUsedOnceTheMapComes) {
  const sim::Scenario s = seed003();
  LocalizerCore first("scan", config_of(s));
  first.set_beacon_map(BeaconMap(s.beacon_list()));
  drive(first, s, "first", 1, s.duration_s);
  const BeaconCalibration found = first.calibration();
  ASSERT_EQ(found.groups.size(), s.local_group_frames_map.size());

  LocalizerCore later("scan", config_of(s));
  EXPECT_TRUE(later.on_calibration(found));
  EXPECT_FALSE(later.on_calibration(found));  // the same again: nothing new
  EXPECT_EQ(later.calibration_revision(), 1u);
  later.set_beacon_map(BeaconMap(s.beacon_list()));
  TofDecoder decoder = scenario_decoder(s);
  std::optional<EstimatorInput> held_back;  // a range delivered 300 ms late
  bool delivered_late = false;
  const std::vector<SourceEvent> events = simulate(s, 2, 40.0);
  ASSERT_FALSE(events.empty());
  const StampNs start_ns = events.front().stamp_ns;
  for (const SourceEvent& e : events) {
    const double t_s = ns_to_s(e.stamp_ns - start_ns);
    auto in = estimator_input("second", e, decoder, BeaconInput::kRanges);
    if (!in) continue;
    if (!held_back && !delivered_late && t_s > 30.0 && std::holds_alternative<RangeMeasurement>(*in)) {
      held_back = in;
      continue;
    }
    if (held_back && e.stamp_ns > stamp_of(*held_back) + 300 * kNsPerMillisecond) {
      later.on_input("second", std::move(*held_back));
      held_back.reset();
      delivered_late = true;
    }
    later.on_input("second", std::move(*in));
    ASSERT_EQ(calibrated_groups(later, "second"), static_cast<double>(found.groups.size()))
        << "at " << t_s << " s";
  }
  EXPECT_GT(later.replays(), 0u) << "accepted " << later.counts().accepted() << ", refused "
                                 << later.counts().rejected_total();
  EXPECT_EQ(later.calibration(), found);  // nothing found by its own robot replaced it
  EXPECT_EQ(later.calibration_revision(), 1u);
}

// Refused whole and counted: a calibration check_calibration refuses, and one that would put a
// beacon in two groups once merged. A group the map does not hold is kept (a map may come back)
// and never used.
TEST(ScanCalibrationSharing, ABrokenCalibrationIsRefusedAndOneOffTheMapIsNeverUsed) {
  const sim::Scenario s = seed003();
  LocalizerCore core("scan", config_of(s));
  core.set_beacon_map(BeaconMap(s.beacon_list()));
  GroupCalibration g;
  g.group = 3;
  for (std::uint32_t id : {31u, 32u, 33u, 34u}) {
    CalibratedBeacon b;
    b.id = id;
    b.position_map_m = Eigen::Vector3d(12.0, 2.0, 3.5);
    g.beacons.push_back(b);
  }
  BeaconCalibration broken{{g}};
  broken.groups[0].transform(0) = std::nan("");
  EXPECT_FALSE(core.on_calibration(broken));
  EXPECT_EQ(core.counts().rejected("calibration.non_finite"), 1u);
  ASSERT_TRUE(core.on_calibration(BeaconCalibration{{g}}));
  GroupCalibration twice = g;  // group 4 claiming group 3's beacons
  twice.group = 4;
  EXPECT_FALSE(core.on_calibration(BeaconCalibration{{twice}}));
  EXPECT_EQ(core.counts().rejected("calibration.duplicate_beacon"), 1u);
  GroupCalibration elsewhere = g;  // a group this map does not have
  elsewhere.group = 77;
  for (auto& b : elsewhere.beacons) b.id += 1000;
  ASSERT_TRUE(core.on_calibration(BeaconCalibration{{elsewhere}}));
  EXPECT_EQ(core.calibration().groups.size(), 2u);
  EXPECT_EQ(core.calibration_groups_unfit(), std::vector<std::uint32_t>{77});
  OdometrySample standing;
  standing.stamp_ns = 1;
  standing.wheel_base_m = 0.5;
  core.on_odometry("robot", standing);
  EXPECT_EQ(calibrated_groups(core, "robot"), 1.0);  // group 3 only
}

}  // namespace
}  // namespace beaconloc::scan
