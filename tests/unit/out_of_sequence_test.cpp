// Late measurements fused at their own stamp (core/out_of_sequence_fusion.hpp): delivered late
// and out of order, ranges and scans leave each estimator exactly where in-order delivery does,
// once they have all arrived; too late and too early ones are refused by reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/out_of_sequence_fusion.hpp"
#include "offline_run.hpp"
#include "sim/scenario.hpp"
#include "sim/scenario_yaml.hpp"
#include "standing_odometry.hpp"

namespace beaconloc {
namespace {

bool is_measurement(const SourceEvent& e) {
  return e.kind == SourceEvent::Kind::kTof || e.kind == SourceEvent::Kind::kLaserScan;
}

// Poses by odometry stamp, published by the decoder and localizer cores fed in this order; only
// the steps at which every measurement stamped at or before the step had arrived (settled).
std::map<StampNs, PoseEstimate> settled_poses(const sim::Scenario& scenario, const std::string& estimator,
                                              const std::vector<SourceEvent>& arrivals,
                                              std::uint64_t* replays = nullptr) {
  std::vector<StampNs> all;
  for (const auto& e : arrivals) {
    if (is_measurement(e)) all.push_back(e.stamp_ns);
  }
  std::sort(all.begin(), all.end());
  std::multiset<StampNs> fed;
  OfflineStack stack(scenario, estimator);
  std::map<StampNs, PoseEstimate> poses;
  for (const auto& e : arrivals) {
    if (is_measurement(e)) fed.insert(e.stamp_ns);
    const auto out = stack.feed("robot", e);
    if (!out) continue;
    const auto due = std::upper_bound(all.begin(), all.end(), e.stamp_ns) - all.begin();
    const auto arrived = std::distance(fed.begin(), fed.upper_bound(e.stamp_ns));
    if (due == arrived) poses[e.stamp_ns] = out->estimate;
  }
  if (replays) *replays = stack.localizer.replays();
  return poses;
}

// min_settled: poses compared before the end (scans at 45 Hz, each up to 200 ms late, leave
// none settled in the UKF's run but the closing one).
void expect_same_as_in_order(const sim::Scenario& scenario, const std::string& estimator, double duration_s,
                             std::size_t min_settled) {
  auto events = simulate(scenario, 3, duration_s);
  // A closing odometry sample after every measurement: its pose is settled in both runs.
  SourceEvent closing;
  for (const auto& e : events) {
    if (e.kind == SourceEvent::Kind::kOdometry) closing = e;
  }
  closing.stamp_ns += 10 * kNsPerMillisecond;  // one odometry period
  closing.odometry.stamp_ns = closing.stamp_ns;
  Delivery late;
  late.max_measurement_delay_ns = 200 * kNsPerMillisecond;  // the worst case
  std::uint64_t replays = 0;
  auto delayed_events = deliver(events, late, 3);
  events.push_back(closing);
  delayed_events.push_back(closing);
  const auto in_order = settled_poses(scenario, estimator, events);
  const auto delayed = settled_poses(scenario, estimator, delayed_events, &replays);
  ASSERT_TRUE(delayed.count(closing.stamp_ns)) << estimator;
  EXPECT_GT(replays, 20u);
  std::size_t compared = 0;
  for (const auto& [stamp, pose] : delayed) {
    const auto it = in_order.find(stamp);
    ASSERT_NE(it, in_order.end());
    // The same calls in the same order: the same bits.
    EXPECT_EQ(pose.pose_map_base, it->second.pose_map_base) << estimator << " at " << stamp;
    EXPECT_EQ(pose.covariance, it->second.covariance) << estimator << " at " << stamp;
    ++compared;
  }
  EXPECT_GE(compared, min_settled + 1) << estimator;
}

TEST(OutOfSequenceFusion, RangeEkfFusesLateRangesExactlyAsInOrder) {
  expect_same_as_in_order(sim::default_scenario(), "range_ekf", 20.0, 100);
}

TEST(OutOfSequenceFusion, DuhlFusesLateRangesExactlyAsInOrder) {
  expect_same_as_in_order(sim::default_scenario(), "duhl", 20.0, 100);
}

TEST(OutOfSequenceFusion, UkfFusesLateScansAndAnonymousRangesExactlyAsInOrder) {
  expect_same_as_in_order(sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) +
                                                  "/examples/scenarios/seed001_classroom.yaml"),
                          "ukf_lrf", 4.0, 0);
}

OdometrySample still_odometry(StampNs stamp_ns) { return standing_odometry(stamp_ns, 0.33, 1e-6); }

TEST(OutOfSequenceFusion, RefusesMeasurementsOlderThanTheHorizonOrAheadOfIt) {
  EstimatorConfig config;
  config.receivers = sim::default_scenario().receivers;
  OutOfSequenceOptions options;
  options.horizon_ns = 600 * kNsPerMillisecond;
  OutOfSequenceFusion fusion(EstimatorRegistry::instance().create("range_ekf", config), options);
  fusion.set_beacon_map(BeaconMap(sim::default_scenario().beacons));
  for (StampNs t = 0; t <= 2 * kNsPerSecond; t += 10 * kNsPerMillisecond) {
    ASSERT_TRUE(fusion.push(still_odometry(t)).accepted);
  }
  RangeMeasurement r;
  r.beacon_id = sim::default_scenario().beacons.front().id;
  r.range_m = 2.0;
  r.variance_m2 = 1e-4;
  r.stamp_ns = 2 * kNsPerSecond - 700 * kNsPerMillisecond;
  EXPECT_EQ(fusion.push(r).rejection, Rejection::kTooLate);
  r.stamp_ns = 2 * kNsPerSecond + 700 * kNsPerMillisecond;
  EXPECT_EQ(fusion.push(r).rejection, Rejection::kAheadOfOdometry);
  r.stamp_ns = 2 * kNsPerSecond - 500 * kNsPerMillisecond;
  EXPECT_TRUE(fusion.push(r).accepted);
  EXPECT_EQ(fusion.replays(), 1u);
  EXPECT_GE(fusion.replayed_odometry_steps(), 50u);  // 500 ms of odometry at 100 Hz, replayed
}

TEST(OutOfSequenceFusion, ARestartIsNotUndoneByMeasurementsFromBeforeIt) {
  EstimatorConfig config;
  config.receivers = sim::default_scenario().receivers;
  OutOfSequenceFusion fusion(EstimatorRegistry::instance().create("range_ekf", config));
  fusion.set_beacon_map(BeaconMap(sim::default_scenario().beacons));
  for (StampNs t = 0; t <= kNsPerSecond; t += 10 * kNsPerMillisecond) fusion.push(still_odometry(t));
  ASSERT_TRUE(fusion.reset(kNsPerSecond, Pose2(1.0, 0.5, 0.2), 1e-4 * Cov3::Identity()).accepted);
  RangeMeasurement r;
  r.beacon_id = sim::default_scenario().beacons.front().id;
  r.range_m = 2.0;
  r.variance_m2 = 1e-4;
  r.stamp_ns = kNsPerSecond - 100 * kNsPerMillisecond;
  EXPECT_EQ(fusion.push(r).rejection, Rejection::kTooLate);
  EXPECT_EQ(fusion.estimator().estimate()->pose_map_base, Pose2(1.0, 0.5, 0.2));
}

// An initial pose that arrives before any odometry carries a stamp of another clock: it is placed
// when the robot's time line begins, so a stamp far ahead (or behind) cannot decide how long the
// pose counts as fresh. Every estimator that can be placed goes degraded once no range has come
// for its staleness time, whatever the stamp; a negative stamp is refused.
TEST(OutOfSequenceFusion, APoseGivenBeforeOdometryAgesOnTheRobotsClockNotOnItsStamp) {
  for (const std::string name : {"range_ekf", "duhl", "ukf_lrf_beacons_only"}) {
    for (const StampNs stamp_ns : {StampNs{0}, StampNs{1'000'000'000'000'000'000}, 5 * kNsPerSecond}) {
      EstimatorConfig config;
      config.receivers = sim::default_scenario().receivers;
      if (name == "ukf_lrf_beacons_only") config.receivers.receivers_base_m.resize(1);  // one receiver (seed 001)
      OutOfSequenceFusion fusion(EstimatorRegistry::instance().create(name, config));
      fusion.set_beacon_map(BeaconMap(sim::default_scenario().beacons));
      EXPECT_EQ(fusion.reset(-1, Pose2(1.0, 0.5, 0.2), 1e-4 * Cov3::Identity()).rejection, Rejection::kInvalidStamp);
      ASSERT_TRUE(fusion.reset(stamp_ns, Pose2(1.0, 0.5, 0.2), 1e-4 * Cov3::Identity()).accepted) << name;
      const StampNs start_ns = 100 * kNsPerSecond;
      for (StampNs t = start_ns; t <= start_ns + 20 * kNsPerSecond; t += 10 * kNsPerMillisecond) {
        fusion.push(still_odometry(t));
        const auto e = fusion.estimator().estimate();
        ASSERT_TRUE(e) << name << " at " << t;
        EXPECT_LT((e->pose_map_base - Pose2(1.0, 0.5, 0.2)).norm(), 1e-6) << name;
        if (t - start_ns > 2 * kNsPerSecond) {
          ASSERT_NE(e->status, PoseStatus::kOk) << name << ", stamp " << stamp_ns << ", at " << t;
        }
      }
    }
  }
}

}  // namespace
}  // namespace beaconloc
