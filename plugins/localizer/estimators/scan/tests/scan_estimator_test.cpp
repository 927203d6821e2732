// scan (scan/scan_estimator.hpp) on the seed 003 setup, simulated: how it starts, that a
// locally referenced beacon never moves the map pose until its group is calibrated, its refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "offline_run.hpp"
#include "scan/scan_estimator.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc::scan {
namespace {

sim::Scenario seed003() {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed003_scan.yaml");
}

EstimatorConfig config_of(const sim::Scenario& s, std::map<std::string, double> parameters = {}) {
  EstimatorConfig c;
  c.receivers = s.receivers;
  c.parameters = std::move(parameters);
  return c;
}

// The simulated inputs as the localizer would push them (the decoder's ranges).
std::vector<EstimatorInput> inputs(const sim::Scenario& s, double until_s) {
  TofDecoderConfig dc;
  dc.min_range_m = s.min_range_m;
  dc.max_range_m = s.max_range_m;
  dc.range_sigma_m = s.range_sigma_m;
  TofDecoder decoder(dc);
  decoder.set_beacon_map(BeaconMap(s.beacon_list()));
  std::vector<EstimatorInput> out;
  for (const SourceEvent& e : simulate(s, 1, until_s)) {
    if (auto in = estimator_input("robot", e, decoder, BeaconInput::kRanges)) out.push_back(*in);
  }
  return out;
}

TEST(ScanEstimator, StartsFromTwoFixesOfTheFirstGroupOnceTheRobotHasMoved) {
  const sim::Scenario s = seed003();
  ScanEstimator scan(config_of(s));
  EXPECT_EQ(scan.startup_wait()->condition, StartupCondition::kNoBeaconMap);
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  bool saw_needs_motion = false;
  for (const EstimatorInput& in : inputs(s, 6.0)) {
    scan.push(in);
    if (const auto wait = scan.startup_wait(); wait && wait->condition == StartupCondition::kNeedsMotion) {
      saw_needs_motion = true;
      EXPECT_LT(wait->value, wait->limit);
    }
  }
  EXPECT_TRUE(saw_needs_motion);
  ASSERT_TRUE(scan.estimate()) << scan.startup_wait()->describe();
  EXPECT_EQ(scan.status(), PoseStatus::kOk);
}

// Before a group is calibrated its ranges reach only its own frame: the map pose is the same as
// with those ranges left out. (With them fused as if known, at their local coordinates, the pose
// would jump by the group's offset, metres.)
TEST(ScanEstimator, AnUncalibratedGroupsRangesNeverMoveTheMapPose) {
  const sim::Scenario s = seed003();
  const BeaconMap map(s.beacon_list());
  ScanEstimator all(config_of(s)), without(config_of(s));
  all.set_beacon_map(map);
  without.set_beacon_map(map);
  int local_ranges = 0;
  for (const EstimatorInput& in : inputs(s, 18.0)) {  // into LRULPS 1's coverage, before its overlap ends
    all.push(in);
    if (const auto* r = std::get_if<RangeMeasurement>(&in); r && map.find_local(r->beacon_id)) {
      ++local_ranges;
      continue;
    }
    without.push(in);
  }
  EXPECT_GT(local_ranges, 20);
  EXPECT_TRUE(all.calibration().groups.empty());
  ASSERT_TRUE(all.estimate());
  EXPECT_EQ(all.estimate()->pose_map_base, without.estimate()->pose_map_base);
  EXPECT_EQ(all.estimate()->covariance, without.estimate()->covariance);
}

TEST(ScanEstimator, RefusesWhatItCannotUseByReason) {
  const sim::Scenario s = seed003();
  EstimatorConfig two = config_of(s);
  two.receivers.receivers_base_m.push_back(Eigen::Vector2d(0.1, 0.0));
  EXPECT_THROW(ScanEstimator{two}, std::invalid_argument);  // one receiver (Sec. 5)
  ScanEstimator scan(config_of(s));
  RangeMeasurement r;
  r.stamp_ns = 2'000'000'000;
  r.beacon_id = 31;
  r.range_m = 4.0;
  r.variance_m2 = 2.5e-5;
  EXPECT_EQ(scan.update(r).rejection, Rejection::kNoBeaconMap);
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  EXPECT_TRUE(scan.update(r).accepted);  // a local beacon: kept for its group's frame
  RangeMeasurement unknown = r;
  unknown.beacon_id = 99;
  EXPECT_EQ(scan.update(unknown).rejection, Rejection::kUnknownBeacon);
  RangeMeasurement receiver = r;
  receiver.receiver_id = 1;
  EXPECT_EQ(scan.update(receiver).rejection, Rejection::kUnknownReceiver);
  RangeMeasurement anonymous = r;
  anonymous.beacon_id = kBeaconUnidentified;
  EXPECT_EQ(scan.update(anonymous).rejection, Rejection::kUnassociatedRange);
  OdometrySample o;
  o.stamp_ns = 5'000'000'000;
  o.wheel_base_m = 0.33;
  ASSERT_TRUE(scan.predict(o).accepted);
  RangeMeasurement stale = r;
  stale.beacon_id = 32;
  stale.stamp_ns = 1'000'000'000;
  EXPECT_EQ(scan.update(stale).rejection, Rejection::kStaleRange);
}

// The whole drive: every LRULPS calibrated, a copy goes on as the original does.
TEST(ScanEstimator, CalibratesEveryGroupOnTheDriveAndACloneGoesOnAlike) {
  const sim::Scenario s = seed003();
  ScanEstimator scan(config_of(s));
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  const std::vector<EstimatorInput> all = inputs(s, s.duration_s);
  std::unique_ptr<Estimator> copy;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (i == all.size() / 2) copy = scan.clone();
    if (copy) copy->push(all[i]);
    scan.push(all[i]);
  }
  EXPECT_EQ(scan.calibration().groups.size(), s.local_group_frames_map.size());
  EXPECT_TRUE(check_calibration(scan.calibration()).ok());
  ASSERT_TRUE(copy && copy->estimate() && scan.estimate());
  EXPECT_EQ(copy->estimate()->pose_map_base, scan.estimate()->pose_map_base);
  EXPECT_EQ(dynamic_cast<ScanEstimator&>(*copy).calibration(), scan.calibration());
  const std::vector<Estimator::StateValue> values = scan.state_values();
  ASSERT_EQ(values.size(), 1u);
  EXPECT_EQ(values[0].value, static_cast<double>(s.local_group_frames_map.size()));
}

}  // namespace
}  // namespace beaconloc::scan
