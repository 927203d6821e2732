// The localizer core: one estimator per robot on shared topics, robot filtering, counts.
#include "localizer_core.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "beaconloc/core/estimator_registry.hpp"
#include "offline_pipeline.hpp"
#include "offline_run.hpp"
#include "sim/scenario.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {
namespace {

TEST(LocalizerCore, UnknownEstimatorFailsAtConstruction) {
  EXPECT_THROW(LocalizerCore("nope", EstimatorConfig{}), UnknownEstimator);
}

TEST(LocalizerCore, KeepsRobotsApartOnSharedTopics) {
  // Two robots on the same path 7 s apart in time; each must be tracked by its own estimator.
  const sim::Scenario scenario = sim::default_scenario();
  testing::OfflineStack stack(scenario);
  const auto ea = testing::simulate(scenario, 1, 20.0);
  auto eb = testing::simulate(scenario, 2, 27.0);
  eb.erase(eb.begin(),
           std::find_if(eb.begin(), eb.end(), [](const auto& e) { return e.stamp_ns > s_to_ns(7.0); }));
  double worst = 0.0;
  std::set<std::uint32_t> used;
  auto feed = [&](const std::string& robot, const SourceEvent& e) {
    if (e.kind == SourceEvent::Kind::kTof) {  // corrections carry the beacons they fused
      if (const auto d = stack.decoder.decode(robot, e.tof); d.range) {
        if (auto corrected = stack.localizer.on_range(robot, d.range->range)) {
          used.insert(corrected->beacons_used.begin(), corrected->beacons_used.end());
        }
      }
      return;
    }
    if (auto pose = stack.feed(robot, e)) {
      if (e.stamp_ns > s_to_ns(robot == "a" ? 3.0 : 10.0)) {
        worst = std::max(worst, (pose->estimate.pose_map_base.head<2>() - e.truth_map_base.head<2>()).norm());
      }
      used.insert(pose->beacons_used.begin(), pose->beacons_used.end());
    }
  };
  for (std::size_t i = 0; i < std::max(ea.size(), eb.size()); ++i) {  // interleaved
    if (i < ea.size()) feed("a", ea[i]);
    if (i < eb.size()) feed("b", eb[i]);
  }
  EXPECT_EQ(stack.localizer.robot_count(), 2u);
  EXPECT_LT(worst, 0.1);
  EXPECT_EQ(used.size(), scenario.beacons.size());
}

TEST(LocalizerCore, IgnoresOtherRobotsWhenFilteredAndCountsThem) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  LocalizerCore core("range_ekf", config, "mine");
  OdometrySample o;
  o.wheel_base_m = 0.33;
  EXPECT_FALSE(core.on_odometry("other", o));
  core.on_range("other", RangeMeasurement{});
  core.on_range("", RangeMeasurement{});
  EXPECT_EQ(core.counts().rejected("odometry.other_robot"), 1u);
  EXPECT_EQ(core.counts().rejected("range.other_robot"), 2u);
  EXPECT_EQ(core.robot_count(), 0u);
}

// A robot handed to another shard: its estimator goes; its next sample starts it afresh.
TEST(LocalizerCore, AReleasedRobotIsForgottenAndStartsAfreshIfItComesBack) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  LocalizerCore core("range_ekf", config);
  OdometrySample o;
  o.wheel_base_m = 0.33;
  core.on_odometry("a", o);
  core.on_odometry("b", o);
  ASSERT_EQ(core.robot_count(), 2u);
  EXPECT_TRUE(core.release_robot("a"));
  EXPECT_FALSE(core.release_robot("a"));
  EXPECT_EQ(core.robot_ids(), std::vector<std::string>{"b"});
  EXPECT_EQ(core.estimator("a"), nullptr);
  core.on_ranges_silent("a");  // a deadline told late: no robot made for it
  core.on_odometry_deadline_missed("a");
  EXPECT_EQ(core.robot_count(), 1u);
  core.on_odometry("a", o);
  EXPECT_EQ(core.robot_count(), 2u);
  EXPECT_FALSE(core.startup_wait("a") == std::nullopt);  // initializing again, from nothing
}

// A robot on the default scenario's data, localized, through its LocalizerCore.
struct LocalizedRobot {
  sim::Scenario scenario = sim::default_scenario();
  LocalizerCore core{"range_ekf", [this] {
                       EstimatorConfig c;
                       c.receivers = scenario.receivers;
                       return c;
                     }()};
  std::vector<SourceEvent> events = simulate(scenario, 2, 12.0);
  TofDecoder decoder;
  std::optional<LocalizerOutput> last;
  LocalizedRobot() {
    core.set_beacon_map(BeaconMap(scenario.beacons));
    decoder.set_beacon_map(BeaconMap(scenario.beacons));
  }
  // Feeds events with stamps in [from_s, to_s), shifted by shift_ns.
  void feed(double from_s, double to_s, StampNs shift_ns = 0) {
    for (auto e : events) {
      if (e.stamp_ns < s_to_ns(from_s) || e.stamp_ns >= s_to_ns(to_s)) continue;
      if (e.kind == SourceEvent::Kind::kOdometry) {
        e.odometry.stamp_ns += shift_ns;
        if (auto out = core.on_odometry("r", e.odometry)) last = out;
      } else if (e.kind == SourceEvent::Kind::kTof) {
        e.tof.fire_stamp_ns += shift_ns;
        if (const auto d = decoder.decode("r", e.tof); d.range) core.on_range("r", d.range->range);
      }
    }
  }
};

// A range that changes the estimate gives the corrected pose at once, at the stamp of the pose
// already given for the newest odometry, naming the beacon; a range gated out gives nothing.
TEST(LocalizerCore, ACorrectionIsPublishedAtOnceAndAGatedRangeIsNot) {
  LocalizedRobot robot;
  robot.feed(0.0, 5.0);
  ASSERT_TRUE(robot.last);
  std::size_t corrections = 0;
  for (auto e : robot.events) {
    if (e.stamp_ns < s_to_ns(5.0) || e.stamp_ns >= s_to_ns(8.0)) continue;
    if (e.kind == SourceEvent::Kind::kOdometry) {
      if (auto out = robot.core.on_odometry("r", e.odometry)) robot.last = out;
      continue;
    }
    if (e.kind != SourceEvent::Kind::kTof) continue;
    const auto d = robot.decoder.decode("r", e.tof);
    if (!d.range) continue;
    const PoseEstimate before = robot.last->estimate;
    const auto corrected = robot.core.on_range("r", d.range->range);
    if (!corrected) continue;
    ++corrections;
    EXPECT_EQ(corrected->estimate.stamp_ns, before.stamp_ns);
    EXPECT_LT(corrected->estimate.covariance.trace(), before.covariance.trace());
    EXPECT_EQ(corrected->beacons_used, std::vector<std::uint32_t>{d.range->range.beacon_id});
    robot.last = corrected;
  }
  EXPECT_GE(corrections, 30u);  // 3 s of beacon slots at 5 Hz, several receivers each

  RangeMeasurement far = {};
  far.stamp_ns = robot.last->estimate.stamp_ns;
  far.beacon_id = robot.scenario.beacons.front().id;
  far.receiver_id = 0;
  far.range_m = 100.0;  // nowhere near: gated out
  far.variance_m2 = 1e-4;
  EXPECT_FALSE(robot.core.on_range("r", far));
}

// Silent ranges (the participant's beacon_range deadline) make the poses degraded at once; the
// next range clears it.
TEST(LocalizerCore, SilentRangesDegradeThePoseUntilARangeArrives) {
  LocalizedRobot robot;
  robot.feed(0.0, 5.0);
  ASSERT_TRUE(robot.last);
  EXPECT_EQ(robot.last->estimate.status, PoseStatus::kOk);
  robot.core.on_ranges_silent("r");
  robot.feed(5.0, 5.05);  // odometry only within 50 ms: no beacon fires in that window
  EXPECT_EQ(robot.last->estimate.status, PoseStatus::kDegraded);
  EXPECT_EQ(robot.core.worst_status(), PoseStatus::kDegraded);
  robot.feed(5.05, 6.0);
  EXPECT_EQ(robot.last->estimate.status, PoseStatus::kOk);
}

// Odometry that stops (its reader's deadline missed kOdometrySilentAfterMisses times in a row: a
// gateway stopped or hung) degrades the robot and names it; a stall of a missed deadline or two
// does not; the next odometry sample clears it.
TEST(LocalizerCore, SilentOdometryDegradesTheRobotUntilOdometryArrives) {
  LocalizedRobot robot;
  robot.feed(0.0, 5.0);
  ASSERT_TRUE(robot.last);
  EXPECT_EQ(robot.core.worst_status(), PoseStatus::kOk);
  for (int i = 1; i < LocalizerCore::kOdometrySilentAfterMisses; ++i) robot.core.on_odometry_deadline_missed("r");
  EXPECT_EQ(robot.core.worst_status(), PoseStatus::kOk);  // a stall, not a dead input
  EXPECT_TRUE(robot.core.odometry_silent_robots().empty());
  robot.core.on_odometry_deadline_missed("r");
  EXPECT_EQ(robot.core.worst_status(), PoseStatus::kDegraded);
  EXPECT_EQ(robot.core.odometry_silent_robots(), std::vector<std::string>{"r"});
  robot.core.on_odometry_deadline_missed("nobody");  // a robot it never heard: nothing to mark
  robot.feed(5.0, 5.5);
  EXPECT_EQ(robot.core.worst_status(), PoseStatus::kOk);
  EXPECT_TRUE(robot.core.odometry_silent_robots().empty());
}

// The robot's clock steps back 30 s (a gateway restarted on a replayed clock): one sample is
// refused as out of order, the next confirms the jump, and the robot's estimator starts over
// from a global fix on the new time line instead of refusing every sample from then on.
TEST(LocalizerCore, AClockThatJumpsBackRestartsTheRobotInsteadOfRefusingEverything) {
  LocalizedRobot robot;
  robot.feed(0.0, 6.0, s_to_ns(30.0));
  ASSERT_TRUE(robot.last);
  robot.decoder = TofDecoder();  // the decoder has its own time line (tested with the decoder)
  robot.decoder.set_beacon_map(BeaconMap(robot.scenario.beacons));
  robot.last.reset();
  robot.feed(6.0, 12.0);
  EXPECT_EQ(robot.core.counts().rejected("odometry.clock_jumped_back"), 1u);
  EXPECT_EQ(robot.core.counts().rejected("odometry.out_of_order_odometry"), 1u);
  ASSERT_TRUE(robot.last);
  EXPECT_LT(robot.last->estimate.stamp_ns, s_to_ns(12.0));  // on the new time line
  EXPECT_EQ(robot.last->estimate.status, PoseStatus::kOk);
  // A sample a little out of order is refused and restarts nothing.
  OdometrySample late = robot.events.front().odometry;
  late.stamp_ns = robot.last->estimate.stamp_ns - 5 * kNsPerMillisecond;
  late.wheel_base_m = 0.33;
  EXPECT_FALSE(robot.core.on_odometry("r", late));
  EXPECT_EQ(robot.core.counts().rejected("odometry.clock_jumped_back"), 1u);
}

}  // namespace
}  // namespace beaconloc
