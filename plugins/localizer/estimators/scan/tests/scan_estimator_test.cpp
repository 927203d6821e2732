// scan (scan/scan_estimator.hpp) on the seed 003 setup, simulated: how it starts, that a
// locally referenced beacon never moves the map pose until its group is calibrated, its refusals.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "offline_run.hpp"
#include "beaconloc/core/chi_square.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "scan/inverse_trajectory.hpp"
#include "scan/scan_estimator.hpp"
#include "sim/scenario_yaml.hpp"
#include "sim/sim_source.hpp"

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
  TofDecoder decoder = scenario_decoder(s);
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

// When the robot is first localized on these inputs (the stamp of the input that did it).
std::optional<StampNs> first_pose_ns(const sim::Scenario& s, const std::vector<EstimatorInput>& in) {
  ScanEstimator scan(config_of(s));
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  for (const EstimatorInput& i : in) {
    scan.push(i);
    if (scan.estimate()) return stamp_of(i);
  }
  return std::nullopt;
}

// An echo (a range 1 m long) on every other range of one of GRULPS 1's five beacons: each echo
// is left out of its epoch's fix (no range rate: it grew more than the robot moved) and is not
// the next range's predecessor, so every fix stands on the other four and the robot starts
// when it does without them, give or take the epoch's last instant (an echo left out may have
// been its last range; within the epoch window). (Given a rate, an echo spoiled its epoch's fix
// and, through the next range's rate, the next one's: the robot never started.) The echo's
// stamp is still a duplicate when repeated, and the echoes are refused by reason.
TEST(ScanEstimator, AnEchoSpoilsNeitherItsEpochsFixNorTheNextOnes) {
  const sim::Scenario s = seed003();
  const std::vector<EstimatorInput> clean = inputs(s, 8.0);
  std::vector<EstimatorInput> echoed = clean;
  int heard = 0;
  std::optional<RangeMeasurement> an_echo;
  for (EstimatorInput& i : echoed) {
    auto* r = std::get_if<RangeMeasurement>(&i);
    if (r && r->beacon_id == 11 && heard++ % 2 == 1) {
      r->range_m += 1.0;
      if (!an_echo) an_echo = *r;
    }
  }
  ASSERT_GE(heard, 6);
  const std::optional<StampNs> started = first_pose_ns(s, clean);
  ASSERT_TRUE(started);
  const std::optional<StampNs> started_with_echoes = first_pose_ns(s, echoed);
  ASSERT_TRUE(started_with_echoes);
  EXPECT_LE(std::abs(*started_with_echoes - *started), 100'000'000);
  ScanEstimator scan(config_of(s));
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  for (const EstimatorInput& i : echoed) {
    scan.push(i);
    if (std::holds_alternative<RangeMeasurement>(i) && std::get<RangeMeasurement>(i).stamp_ns == an_echo->stamp_ns &&
        std::get<RangeMeasurement>(i).beacon_id == 11) {
      break;
    }
  }
  EXPECT_EQ(scan.update(*an_echo).rejection, Rejection::kDuplicateRange);
  // The next echo is refused as one, by reason.
  std::size_t at = 0;
  while (at < echoed.size() && !(std::holds_alternative<RangeMeasurement>(echoed[at]) &&
                                 std::get<RangeMeasurement>(echoed[at]).stamp_ns == an_echo->stamp_ns)) {
    ++at;
  }
  int refused_as_echo = 0;
  for (std::size_t i = at + 1; i < echoed.size(); ++i) {
    const InputResult result = scan.push(echoed[i]);
    refused_as_echo += !result.accepted && result.rejection == Rejection::kLongerThanTheReceiverMoved;
  }
  EXPECT_GT(refused_as_echo, 0);
}

// An echo too short for the motion check (0.25 m: within what the receiver moves in a group's
// cycle) on every third range of one of the first group's beacons: its epoch's fix leaves it out
// (group_fix.hpp) and counts it: the robot starts within the epoch window of its clean start
// (before, it started 0.76 s late, a group cycle: checked). With two of the group's five beacons
// silent, an epoch has no range to spare and the echo's is lost, but the clean range after the
// echo, too much shorter than it, takes its rate from the range before the echo, so that the next
// epoch is fixed: the robot starts at most a cycle late (taking no rate, 3.04 s late: checked).
TEST(ScanEstimator, AnEchoWithinTheMotionCostsNoFix) {
  const sim::Scenario s = seed003();
  const std::vector<EstimatorInput> clean = inputs(s, 12.0);
  const auto with_echoes = [](std::vector<EstimatorInput> in) {
    int heard = 0;
    for (EstimatorInput& i : in) {
      auto* r = std::get_if<RangeMeasurement>(&i);
      if (r && r->beacon_id == 11 && heard++ % 3 == 1) r->range_m += 0.25;
    }
    return in;
  };
  const auto without_beacons_14_and_15 = [](std::vector<EstimatorInput> in) {
    in.erase(std::remove_if(in.begin(), in.end(),
                            [](const EstimatorInput& i) {
                              const auto* r = std::get_if<RangeMeasurement>(&i);
                              return r && (r->beacon_id == 14 || r->beacon_id == 15);
                            }),
             in.end());
    return in;
  };
  const std::optional<StampNs> started = first_pose_ns(s, clean);
  ASSERT_TRUE(started);
  const std::optional<StampNs> started_with_echoes = first_pose_ns(s, with_echoes(clean));
  ASSERT_TRUE(started_with_echoes);
  const std::vector<EstimatorInput> three = without_beacons_14_and_15(clean);
  const std::optional<StampNs> three_started = first_pose_ns(s, three);
  ASSERT_TRUE(three_started);
  const std::optional<StampNs> three_started_with_echoes = first_pose_ns(s, with_echoes(three));
  ASSERT_TRUE(three_started_with_echoes);
  std::printf("five beacons: started %.3f s after the clean run; three: %.3f s\n",
              ns_to_s(*started_with_echoes - *started), ns_to_s(*three_started_with_echoes - *three_started));
  EXPECT_LE(std::abs(*started_with_echoes - *started), 100'000'000);
  const StampNs group_cycle_ns = static_cast<StampNs>(s.firing_order.size()) * s.slot_period_ns;
  EXPECT_LE(std::abs(*three_started_with_echoes - *three_started), group_cycle_ns + 100'000'000);
  ScanEstimator scan(config_of(s));
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  for (const EstimatorInput& i : with_echoes(clean)) scan.push(i);
  double left_out = 0.0;
  for (const Estimator::StateValue& v : scan.state_values()) {
    if (v.name == "echoes_left_out_of_fixes") left_out = v.value;
  }
  EXPECT_GT(left_out, 0.0);
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
  ASSERT_EQ(values.size(), 4u);
  EXPECT_EQ(values[0].name, "calibrated_groups");
  EXPECT_EQ(values[0].value, static_cast<double>(s.local_group_frames_map.size()));
  EXPECT_EQ(values[1].name, "inverse_passes");
  EXPECT_EQ(values[1].value, 1.0);  // back in GRULPS 2 for 10 s
  EXPECT_EQ(values[3].name, "echoes_left_out_of_fixes");
}

// Sec. 3.6: the backwards drive starts next to GRULPS 2, so the last groups of the drive are
// calibrated better by it; without it they carry the whole chain's error.
TEST(ScanEstimator, TheInverseTrajectoryCalibratesTheLastGroupsBetter) {
  const sim::Scenario s = seed003();
  const BeaconMap truth(s.beacons);
  const auto last_group_error = [&](double inverse) {
    ScanEstimator scan(config_of(s, {{"inverse_trajectory", inverse}}));
    scan.set_beacon_map(BeaconMap(s.beacon_list()));
    for (const EstimatorInput& in : inputs(s, s.duration_s)) scan.push(in);
    scan.finish();
    for (const GroupCalibration& g : scan.calibration().groups) {
      if (g.group != 9) continue;
      double sum = 0.0;
      for (const CalibratedBeacon& b : g.beacons) {
        sum += (b.position_map_m.head<2>() - truth.find(b.id)->position_map_m.head<2>()).norm();
      }
      return sum / static_cast<double>(g.beacons.size());
    }
    ADD_FAILURE() << "group 9 not calibrated";
    return 0.0;
  };
  const double with = last_group_error(1.0), without = last_group_error(0.0);
  std::printf("LRULPS #7 (group 9), seed 1: %.3f m with the inverse trajectory, %.3f m without\n", with, without);
  EXPECT_LT(with, 0.15);
  EXPECT_LT(with, 0.5 * without);
}

// A global frame the GRULPS contradicts (here: 3 s without ranges while the odometry says the
// robot went twice as fast as it did, 1.2 m off) is found again from two GRULPS fixes, degraded
// meanwhile, never ok while wrong.
TEST(ScanEstimator, AFrameTheGrulpsContradictsIsFoundAgainAndDegradedMeanwhile) {
  const sim::Scenario s = seed003();
  ScanEstimator scan(config_of(s));
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  sim::SimSource source(s, 1);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(14.0), events);
  TofDecoder decoder = scenario_decoder(s);
  bool degraded = false;
  double worst_ok_error_m = 0.0;
  for (const SourceEvent& e : events) {
    const double t = ns_to_s(e.stamp_ns);
    std::optional<EstimatorInput> in = estimator_input("robot", e, decoder, BeaconInput::kRanges);
    if (!in) continue;
    const bool outage = t > 5.0 && t < 8.0;
    if (outage && std::holds_alternative<RangeMeasurement>(*in)) continue;
    if (auto* o = std::get_if<OdometrySample>(&*in); o && outage) {
      o->wheel_velocity_right_mps *= 2.0;
      o->wheel_velocity_left_mps *= 2.0;
    }
    scan.push(*in);
    if (e.kind != SourceEvent::Kind::kOdometry || !e.has_truth || !scan.estimate() || t < 8.0) continue;
    const double error_m = (scan.estimate()->pose_map_base.head<2>() - e.truth_map_base.head<2>()).norm();
    if (scan.status() == PoseStatus::kDegraded) degraded = true;
    if (scan.status() == PoseStatus::kOk && error_m > 0.3) worst_ok_error_m = std::max(worst_ok_error_m, error_m);
  }
  EXPECT_TRUE(degraded);
  ASSERT_TRUE(scan.estimate());
  EXPECT_EQ(scan.status(), PoseStatus::kOk);
  const Pose2 truth = events.back().truth_map_base;
  EXPECT_LT((scan.estimate()->pose_map_base.head<2>() - truth.head<2>()).norm(), 0.1);
  // The filter itself takes the GRULPS ranges again once its covariance has grown enough: an ok
  // pose more than 0.3 m off is a pose the estimator trusted while it was wrong.
  EXPECT_EQ(worst_ok_error_m, 0.0);
}

// A map given again mid-run (a new site) starts everything again: nothing measured against the
// old beacons survives, and an epoch open at the change does not crash it.
TEST(ScanEstimator, ANewMapStartsEverythingAgain) {
  const sim::Scenario s = seed003();
  ScanEstimator scan(config_of(s));
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  const std::vector<EstimatorInput> all = inputs(s, 30.0);
  std::size_t i = 0;
  for (; i < all.size() && scan.calibration().groups.empty(); ++i) scan.push(all[i]);
  ASSERT_FALSE(scan.calibration().groups.empty());
  // Mid-epoch: a range of LRULPS #2 pushed, then a map with GRULPS 1 alone.
  std::vector<Beacon> grulps;
  for (const Beacon& b : s.beacon_list().map_frame) {
    if (b.group == 1) grulps.push_back(b);
  }
  scan.set_beacon_map(BeaconMap(grulps));
  EXPECT_TRUE(scan.calibration().groups.empty());
  EXPECT_FALSE(scan.estimate());
  int refused = 0;
  for (; i < all.size(); ++i) refused += scan.push(all[i]).accepted ? 0 : 1;
  EXPECT_GT(refused, 0);  // the LRULPS ranges: unknown_beacon now
  EXPECT_TRUE(scan.calibration().groups.empty());
}

TEST(ScanEstimator, DuplicatesFloodsAndRangesFromTheFutureAreRefusedByReason) {
  const sim::Scenario s = seed003();
  ScanEstimator scan(config_of(s));
  scan.set_beacon_map(BeaconMap(s.beacon_list()));
  OdometrySample o;
  o.stamp_ns = 1'000'000'000;
  o.wheel_base_m = 0.33;
  ASSERT_TRUE(scan.predict(o).accepted);
  RangeMeasurement r;
  r.stamp_ns = 1'005'000'000;
  r.beacon_id = 11;
  r.range_m = 4.0;
  r.variance_m2 = 2.5e-5;
  EXPECT_TRUE(scan.update(r).accepted);
  EXPECT_EQ(scan.update(r).rejection, Rejection::kDuplicateRange);
  RangeMeasurement ahead = r;
  ahead.stamp_ns = 60'000'000'000;
  EXPECT_EQ(scan.update(ahead).rejection, Rejection::kAheadOfOdometry);
  // A flood: 100 beacons of one group heard within 1 ms (a hostile map, a broken gateway): the
  // epoch takes 64 (no ULPS has more) and refuses the rest by reason.
  std::vector<Beacon> big;
  for (std::uint32_t id = 1; id <= 100; ++id) big.push_back({id, {0.01 * id, 0.0, 3.5}, 1});
  ScanEstimator flooded(config_of(s));
  flooded.set_beacon_map(BeaconMap(big));
  ASSERT_TRUE(flooded.predict(o).accepted);
  int refused = 0;
  for (std::uint32_t id = 1; id <= 100; ++id) {
    RangeMeasurement flood = r;
    flood.beacon_id = id;
    flood.stamp_ns = r.stamp_ns + id * 10'000;
    const InputResult result = flooded.update(flood);
    if (!result.accepted) {
      EXPECT_EQ(result.rejection, Rejection::kTooManyRangesInEpoch);
      ++refused;
    }
  }
  EXPECT_EQ(refused, 36);
}

// A robot (seed) driving the seed 003 path with a calibration it is given, scored where the
// nearest group is an LRULPS (#1 to #7).
struct CalibratedDrive {
  std::size_t scored = 0, ok = 0;
  std::size_t ok_outside_3_sigma = 0;  // ok poses whose error is outside their 3-sigma ellipse
  double rms_m = NAN;
  double ok_sigma_rms_m = NAN;  // the ok poses' position sigma
};
CalibratedDrive drive_with(const sim::Scenario& s, ScanEstimator& robot, std::uint64_t seed) {
  TofDecoder decoder = scenario_decoder(s);
  CalibratedDrive out;
  double sum2 = 0.0, ok_variance_sum = 0.0;
  for (const SourceEvent& e : simulate(s, seed, s.duration_s)) {
    if (auto in = estimator_input("robot", e, decoder, BeaconInput::kRanges)) robot.push(*in);
    const bool in_lrulps = s.nearest_group_is_local(e.truth_map_base.x(), e.truth_map_base.y());
    if (e.kind != SourceEvent::Kind::kOdometry || !e.has_truth || !in_lrulps || !robot.estimate()) continue;
    const PoseEstimate est = *robot.estimate();
    const Eigen::Vector2d error = est.pose_map_base.head<2>() - e.truth_map_base.head<2>();
    sum2 += error.squaredNorm();
    ++out.scored;
    if (est.status != PoseStatus::kOk) continue;
    ++out.ok;
    const Eigen::Matrix2d p = est.covariance.topLeftCorner<2, 2>();
    ok_variance_sum += p.trace();
    out.ok_outside_3_sigma += error.dot(p.ldlt().solve(error)) > kChiSquare2Dof3Sigma ? 1 : 0;
  }
  out.rms_m = std::sqrt(sum2 / static_cast<double>(std::max<std::size_t>(out.scored, 1)));
  out.ok_sigma_rms_m = std::sqrt(ok_variance_sum / static_cast<double>(std::max<std::size_t>(out.ok, 1)));
  return out;
}

BeaconCalibration calibrated_by_seed(const sim::Scenario& s, std::uint64_t seed) {
  ScanEstimator first(config_of(s));
  first.set_beacon_map(BeaconMap(s.beacon_list()));
  TofDecoder decoder = scenario_decoder(s);
  for (const SourceEvent& e : simulate(s, seed, s.duration_s)) {
    if (auto in = estimator_input("robot", e, decoder, BeaconInput::kRanges)) first.push(*in);
  }
  first.finish();
  return first.calibration();
}

double group_error_m(const sim::Scenario& s, const BeaconCalibration& c, std::uint32_t group) {
  const BeaconMap truth(s.beacons);
  for (const GroupCalibration& g : c.groups) {
    if (g.group != group) continue;
    double sum = 0.0;
    for (const CalibratedBeacon& b : g.beacons) sum += (b.position_map_m.head<2>() - truth.find(b.id)->position_map_m.head<2>()).norm();
    return sum / static_cast<double>(g.beacons.size());
  }
  return NAN;
}

// Acceptance (issue 16): a second robot given the first one's calibration localizes in the
// calibrated groups at once, with no calibration drive of its own; its accuracy there is reported.
TEST(ScanEstimator, ASecondRobotGivenTheCalibrationLocalizesInTheCalibratedGroupsAtOnce) {
  const sim::Scenario s = seed003();
  const BeaconMap map(s.beacon_list());
  const BeaconCalibration calibration = calibrated_by_seed(s, 1);
  ASSERT_EQ(calibration.groups.size(), s.local_group_frames_map.size());

  // The second robot: another seed (other noise), the same drive.
  ScanEstimator second(config_of(s));
  second.set_beacon_map(map);
  ASSERT_TRUE(second.use_calibration(calibration));
  const CalibratedDrive d = drive_with(s, second, 2);
  ASSERT_GT(d.scored, 6000u);  // ~70 s of the 98 s drive at 100 Hz
  std::printf("second robot in the calibrated groups (seed 2, 100 Hz poses): position RMS %.3f m, %.0f %% ok; ok "
              "poses: position sigma RMS %.3f m, %.1f %% outside their 3-sigma ellipse\n",
              d.rms_m, 100.0 * static_cast<double>(d.ok) / static_cast<double>(d.scored), d.ok_sigma_rms_m,
              100.0 * static_cast<double>(d.ok_outside_3_sigma) / static_cast<double>(std::max<std::size_t>(d.ok, 1)));
  EXPECT_LT(d.rms_m, 0.5);
  EXPECT_GT(d.ok, d.scored * 9 / 10);
  // Never ok while wrong: an ok pose's covariance holds the calibration's error (0 % on seed 2;
  // 56 % before the calibrated beacons' shared error was added to what the pose reports).
  EXPECT_LT(d.ok_outside_3_sigma, d.ok / 100);
  // It calibrated nothing itself: its calibration is the one it was given.
  EXPECT_EQ(second.calibration(), calibration);

  // A calibration that does not fit the map is refused whole.
  BeaconCalibration wrong = calibration;
  wrong.groups[0].beacons.pop_back();
  ScanEstimator third(config_of(s));
  third.set_beacon_map(map);
  EXPECT_FALSE(third.use_calibration(wrong));
  wrong = calibration;
  wrong.groups[0].group = 1;  // a GRULPS
  EXPECT_FALSE(third.use_calibration(wrong));
  EXPECT_TRUE(third.calibration().groups.empty());
}

// The same with a bad calibration: the first of seeds 1-40 whose LRULPS #4 is more than 0.5 m
// off. A robot using it is as far off there as its beacons, and its covariance says so: never ok
// outside its 3-sigma ellipse.
TEST(ScanEstimator, ASecondRobotGivenABadCalibrationIsOffAndSaysSo) {
  const sim::Scenario s = seed003();
  std::optional<BeaconCalibration> bad;
  std::uint64_t bad_seed = 0;
  for (std::uint64_t seed = 1; seed <= 40 && !bad; ++seed) {
    BeaconCalibration c = calibrated_by_seed(s, seed);
    if (c.groups.size() == s.local_group_frames_map.size() && group_error_m(s, c, 6) > 0.5) {
      bad = c;
      bad_seed = seed;
    }
  }
  ASSERT_TRUE(bad) << "no seed in 1-40 calibrates LRULPS #4 worse than 0.5 m";
  ScanEstimator second(config_of(s));
  second.set_beacon_map(BeaconMap(s.beacon_list()));
  ASSERT_TRUE(second.use_calibration(*bad));
  const CalibratedDrive d = drive_with(s, second, 2);
  std::printf("calibration of seed %llu (LRULPS #4 %.3f m off), second robot: position RMS %.3f m, %.0f %% ok; ok poses: "
              "position sigma RMS %.3f m, %.1f %% outside their 3-sigma ellipse\n",
              static_cast<unsigned long long>(bad_seed), group_error_m(s, *bad, 6), d.rms_m,
              100.0 * static_cast<double>(d.ok) / static_cast<double>(std::max<std::size_t>(d.scored, 1)),
              d.ok_sigma_rms_m,
              100.0 * static_cast<double>(d.ok_outside_3_sigma) / static_cast<double>(std::max<std::size_t>(d.ok, 1)));
  EXPECT_LT(d.ok_outside_3_sigma, d.ok / 100);
}

TEST(InputLog, KeepsEveryItemNewestFirstAndCopiesShareTheSealedPart) {
  InputLog<int> log;
  for (int i = 0; i < 1000; ++i) log.push_back(i);
  InputLog<int> copy = log;
  copy.push_back(1000);
  std::vector<int> seen;
  log.newest_first([&](int v) { seen.push_back(v); });
  ASSERT_EQ(seen.size(), 1000u);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], 999 - i);
  int first = -1;
  copy.newest_first([&](int v) {
    if (first < 0) first = v;
  });
  EXPECT_EQ(first, 1000);
  EXPECT_EQ(copy.size(), 1001u);
  copy.clear();
  EXPECT_TRUE(copy.empty());
  EXPECT_EQ(log.size(), 1000u);  // the original keeps its items
}

// The backwards drive: stamps mirrored from the newest, ranges as they were, each odometry
// sample carrying the next one's wheel speeds negated (the interval it now covers), and the
// dead-reckoned path driven backwards ends where the forward one began.
TEST(InverseTrajectory, TheInputsAreTheDriveBackwards) {
  InputLog<RecordedInput> log;
  Pose2 forward = Pose2::Zero();
  for (int k = 0; k <= 300; ++k) {
    OdometrySample o;
    o.stamp_ns = StampNs{1'000'000'000} + StampNs{k} * 10'000'000;
    o.wheel_base_m = 0.33;
    o.wheel_velocity_right_mps = 0.4 + 0.001 * k;
    o.wheel_velocity_left_mps = 0.35;
    if (k > 0) forward = predict_diff_drive(forward, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps, 0.33, 0.01).pose;
    log.push_back(o);
    if (k % 7 == 3) {
      RangeMeasurement r;
      r.stamp_ns = o.stamp_ns + 4'000'000;
      r.beacon_id = static_cast<std::uint32_t>(k);
      r.range_m = 2.0 + 0.01 * k;
      r.variance_m2 = 1e-4;
      log.push_back(r);
    }
  }
  const std::vector<RecordedInput> back = reversed_inputs(log);
  ASSERT_EQ(back.size(), log.size());
  StampNs previous = -1;
  Pose2 backwards = forward;  // from where the drive ended
  std::optional<StampNs> last_odometry;
  for (const RecordedInput& in : back) {
    const StampNs t = std::visit([](const auto& x) { return x.stamp_ns; }, in);
    EXPECT_GE(t, previous);
    previous = t;
    if (const auto* o = std::get_if<OdometrySample>(&in)) {
      if (last_odometry) {
        backwards = predict_diff_drive(backwards, o->wheel_velocity_right_mps, o->wheel_velocity_left_mps, 0.33,
                                       ns_to_s(t - *last_odometry))
                        .pose;
      }
      last_odometry = t;
    } else {
      const auto& r = std::get<RangeMeasurement>(in);
      EXPECT_DOUBLE_EQ(r.range_m, 2.0 + 0.01 * r.beacon_id);
      EXPECT_EQ(r.stamp_ns, StampNs{1'000'000'000} + 300 * StampNs{10'000'000} - (1'000'000'000 + static_cast<StampNs>(r.beacon_id) * 10'000'000 + 4'000'000));
    }
  }
  EXPECT_LT(backwards.head<2>().norm(), 1e-9) << backwards.transpose();
  EXPECT_NEAR(backwards.z(), 0.0, 1e-9);
}

}  // namespace
}  // namespace beaconloc::scan
