// The site's calibration in the localizer (LocalizerCore::on_calibration, issue 16 item 3): what
// one robot calibrates reaches every robot the localizer serves, a robot made later starts with
// it, a calibration received before the map is used once the map comes, a late measurement's
// replay does not roll it back, and one that does not fit the map is never used.
#include <gtest/gtest.h>

#include <cstdio>
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
  // A change as a group (or two finished at one sample) is calibrated, then again where the
  // backwards drive found a better one: a handful of changes, not one per sample.
  std::printf("the site's calibration changed %llu times for %zu groups\n",
              static_cast<unsigned long long>(core.calibration_revision()), site.groups.size());
  EXPECT_GE(core.calibration_revision(), site.groups.size() / 2);
  EXPECT_LE(core.calibration_revision(), 2 * site.groups.size());

  // A second robot: its estimator holds every group at its first sample.
  OdometrySample standing;
  standing.stamp_ns = 1;
  standing.wheel_base_m = 0.5;
  core.on_odometry("second", standing);
  EXPECT_EQ(calibrated_groups(core, "second"), static_cast<double>(site.groups.size()));
  EXPECT_EQ(scan_of(core, "second").calibration(), site);
}

// Ranges delivered late (every fifth one 200 ms after its stamp, as the decoder's hop can) are
// fused at their stamps by replays from copies of the estimator; what the site learns is what
// in-order delivery gives, to the last bit, backwards drive included.
TEST(ScanCalibrationSharing, LateRangesChangeNothingTheSiteLearns) {
  const sim::Scenario s = seed003();
  LocalizerCore in_order("scan", config_of(s)), late("scan", config_of(s));
  in_order.set_beacon_map(BeaconMap(s.beacon_list()));
  late.set_beacon_map(BeaconMap(s.beacon_list()));
  drive(in_order, s, "robot", 1, s.duration_s + 12.0);
  TofDecoder decoder = scenario_decoder(s);
  std::vector<EstimatorInput> held;  // in stamp order
  int ranges = 0;
  for (const SourceEvent& e : simulate(s, 1, s.duration_s + 12.0)) {
    auto in = estimator_input("robot", e, decoder, BeaconInput::kRanges);
    if (!in) continue;
    while (!held.empty() && stamp_of(held.front()) + 200 * kNsPerMillisecond <= e.stamp_ns) {
      late.on_input("robot", held.front());
      held.erase(held.begin());
    }
    if (std::holds_alternative<RangeMeasurement>(*in) && ++ranges % 5 == 0) {
      held.push_back(*in);
      continue;
    }
    late.on_input("robot", std::move(*in));
  }
  EXPECT_GT(late.replays(), 100u);
  ASSERT_EQ(in_order.calibration().groups.size(), s.local_group_frames_map.size());
  EXPECT_EQ(late.calibration(), in_order.calibration());
  double passes = 0.0;
  for (const auto& v : late.estimator("robot")->state_values()) {
    if (v.name == "inverse_passes") passes = v.value;
  }
  EXPECT_GE(passes, 1.0);
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

// A calibration of `group` with transform [a, b, tx, ty] (eq. 41), its beacons where it puts the
// map's beacons of that group (eq. 42-43), each with the covariance sigma_m^2 I.
GroupCalibration calibration_of(const BeaconMap& map, std::uint32_t group, const Eigen::Vector4d& t,
                                double sigma_m) {
  GroupCalibration g;
  g.group = group;
  g.transform = t;
  for (const LocalBeacon& lb : map.local_beacons()) {
    if (lb.group != group) continue;
    CalibratedBeacon b;
    b.id = lb.id;
    const Eigen::Vector3d& p = lb.position_group_m;
    b.position_map_m << t(0) * p.x() - t(1) * p.y() + t(2), t(1) * p.x() + t(0) * p.y() + t(3), p.z();
    b.covariance_m2 = sigma_m * sigma_m * Eigen::Matrix2d::Identity();
    g.beacons.push_back(b);
  }
  return g;
}

// Refused and counted: a calibration check_calibration refuses (whole), a group that would put a
// beacon in two groups, a group the map does not hold or whose beacons are not where its
// transform puts the map's (re-surveyed since). Groups received before the map are kept until it
// comes, and those it does not fit are dropped then.
TEST(ScanCalibrationSharing, ABrokenCalibrationIsRefusedAndOneOffTheMapIsNeverUsed) {
  const sim::Scenario s = seed003();
  const BeaconMap map(s.beacon_list());
  const GroupCalibration g = calibration_of(map, 3, Eigen::Vector4d(0.8, 0.6, 12.0, 2.0), 0.05);
  LocalizerCore core("scan", config_of(s));
  BeaconCalibration broken{{g}};
  broken.groups[0].transform(0) = std::nan("");
  EXPECT_FALSE(core.on_calibration(broken));
  EXPECT_EQ(core.counts().rejected("calibration.non_finite"), 1u);
  // Before the map nothing can be checked against it: group 3, and group 77 of another site.
  ASSERT_TRUE(core.on_calibration(BeaconCalibration{{g}}));
  GroupCalibration twice = g;  // group 4 claiming group 3's beacons
  twice.group = 4;
  EXPECT_FALSE(core.on_calibration(BeaconCalibration{{twice}}));
  EXPECT_EQ(core.counts().rejected("calibration.duplicate_beacon"), 1u);
  GroupCalibration elsewhere = g;
  elsewhere.group = 77;
  for (auto& b : elsewhere.beacons) b.id += 1000;
  ASSERT_TRUE(core.on_calibration(BeaconCalibration{{elsewhere}}));
  EXPECT_EQ(core.calibration().groups.size(), 2u);
  const std::uint64_t revision = core.calibration_revision();
  core.set_beacon_map(map);  // group 77 is not on it: dropped, and the site's calibration changed
  EXPECT_EQ(core.calibration(), BeaconCalibration{{g}});
  EXPECT_EQ(core.counts().rejected("calibration.not_on_map"), 1u);
  EXPECT_GT(core.calibration_revision(), revision);
  // With the map: a group it does not hold, and group 4 with its beacons off its transform (its
  // group's frame re-surveyed since, or a sample whose numbers disagree).
  EXPECT_FALSE(core.on_calibration(BeaconCalibration{{elsewhere}}));
  GroupCalibration moved = calibration_of(map, 4, Eigen::Vector4d(1.0, 0.0, 18.5, 2.0), 0.05);
  moved.beacons[0].position_map_m.x() += 0.01;
  EXPECT_FALSE(core.on_calibration(BeaconCalibration{{moved}}));
  EXPECT_EQ(core.counts().rejected("calibration.not_on_map"), 3u);
  OdometrySample standing;
  standing.stamp_ns = 1;
  standing.wheel_base_m = 0.5;
  core.on_odometry("robot", standing);
  EXPECT_EQ(calibrated_groups(core, "robot"), 1.0);  // group 3 only
  EXPECT_EQ(scan_of(core, "robot").calibration(), BeaconCalibration{{g}});
}

// Two localizers that hold different calibrations of one group and hear each other end with the
// same one, the surer, whichever heard the other first; neither hands it back and forth.
TEST(ScanCalibrationSharing, TwoLocalizersKeepTheSameCalibrationOfAGroupWhateverTheOrder) {
  const sim::Scenario s = seed003();
  const BeaconMap map(s.beacon_list());
  const BeaconCalibration surer{{calibration_of(map, 5, Eigen::Vector4d(0.0, 1.0, 25.0, 2.0), 0.02)}};
  const BeaconCalibration looser{{calibration_of(map, 5, Eigen::Vector4d(0.0, 1.0, 25.1, 2.0), 0.05)}};
  for (const bool surer_first : {true, false}) {
    LocalizerCore one("scan", config_of(s)), other("scan", config_of(s));
    one.set_beacon_map(map);
    other.set_beacon_map(map);
    ASSERT_TRUE(one.on_calibration(surer));
    ASSERT_TRUE(other.on_calibration(looser));
    // Each publishes what it holds, the other takes it if it is better, and publishes again if
    // it changed: a few rounds settle it.
    LocalizerCore& first = surer_first ? one : other;
    LocalizerCore& second = surer_first ? other : one;
    int changes = 0;
    for (int round = 0; round < 4; ++round) {
      changes += second.on_calibration(first.calibration()) ? 1 : 0;
      changes += first.on_calibration(second.calibration()) ? 1 : 0;
    }
    EXPECT_EQ(changes, 1) << "surer first " << surer_first;  // the looser one's holder takes the surer, once
    EXPECT_EQ(one.calibration(), surer);
    EXPECT_EQ(other.calibration(), surer);
  }
}

}  // namespace
}  // namespace beaconloc::scan
