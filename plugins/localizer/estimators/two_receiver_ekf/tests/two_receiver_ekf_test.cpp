// two_receiver_ekf (seed 004): what it needs (two receivers apart, an initial pose), that the
// pair's pose converges from the paper's 0.7 m start on exact ranges, and that receivers whose
// estimates contradict the mounting make the pose degraded, never ok; an echo longer than the
// other receiver's range of the same firing allows is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "beaconloc/core/estimator_registry.hpp"
#include "exact_ranges.hpp"
#include "standing_odometry.hpp"

namespace beaconloc {
namespace {

constexpr double kL = 0.133;  // seed 004 Sec. 2

EstimatorConfig two_receivers() {
  EstimatorConfig c;
  c.receivers.receivers_base_m = {{kL, 0.0}, {-kL, 0.0}};
  c.receivers.receiver_height_m = 1.0;
  return c;
}

// Four ceiling generators 4.4 m above the receivers, around the robot.
const BeaconMap kMap({{1, {0.0, 0.0, 5.4}, 0}, {2, {2.0, 0.0, 5.4}, 0}, {3, {0.0, 2.0, 5.4}, 0}, {4, {2.0, 2.0, 5.4}, 0}});

// The estimator of this config, given kMap.
std::unique_ptr<Estimator> on_the_map(const EstimatorConfig& config) {
  auto e = EstimatorRegistry::instance().create("two_receiver_ekf", config);
  e->set_beacon_map(kMap);
  return e;
}

TEST(TwoReceiverEkf, TakesTwoReceiversApartAndWaitsForItsInitialPose) {
  EstimatorConfig one = two_receivers();
  one.receivers.receivers_base_m.resize(1);
  EXPECT_THROW(EstimatorRegistry::instance().create("two_receiver_ekf", one), std::invalid_argument);
  EstimatorConfig three = two_receivers();
  three.receivers.receivers_base_m.push_back({0.0, 0.1});
  EXPECT_THROW(EstimatorRegistry::instance().create("two_receiver_ekf", three), std::invalid_argument);
  EstimatorConfig together = two_receivers();
  together.receivers.receivers_base_m[1] = together.receivers.receivers_base_m[0];
  EXPECT_THROW(EstimatorRegistry::instance().create("two_receiver_ekf", together), std::invalid_argument);

  auto unplaced = EstimatorRegistry::instance().create("two_receiver_ekf", two_receivers());
  EXPECT_FALSE(unplaced->localizes_from_beacons());
  unplaced->set_beacon_map(kMap);
  ASSERT_TRUE(unplaced->predict(standing_odometry(0)).accepted);
  ASSERT_TRUE(unplaced->startup_wait());
  EXPECT_EQ(unplaced->startup_wait()->condition, StartupCondition::kNeedsInitialPose);
  const auto ranges = test_support::exact_ranges(Pose2(1.0, 1.0, 0.0), two_receivers().receivers, *kMap.find(1), 0);
  EXPECT_EQ(unplaced->update(ranges[0]).rejection, Rejection::kNoInitialPose);
  EXPECT_FALSE(unplaced->estimate());
}

// The paper's experiment (Sec. 4): the estimate starts 0.71 m and 0.3 rad from the robot.
TEST(TwoReceiverEkf, ConvergesFromThePapersStartOnExactRanges) {
  const Pose2 truth(1.0, 1.2, 0.8);
  EstimatorConfig config = two_receivers();
  config.initial_pose = Pose2(0.5, 0.7, 0.5);
  auto e = on_the_map(config);
  StampNs t = 0;
  for (int cycle = 0; cycle < 40; ++cycle) {
    for (const Beacon& b : kMap.beacons()) {
      t += 50 * kNsPerMillisecond;
      ASSERT_TRUE(e->predict(standing_odometry(t, 0.3, 1e-6)).accepted);
      for (const RangeMeasurement& r : test_support::exact_ranges(truth, config.receivers, b, t)) {
        const InputResult u = e->update(r);
        EXPECT_TRUE(u.accepted) << to_string(*u.rejection) << " cycle " << cycle;
      }
    }
  }
  const auto estimate = e->estimate();
  ASSERT_TRUE(estimate);
  EXPECT_EQ(estimate->status, PoseStatus::kOk);
  EXPECT_LT((estimate->pose_map_base.head<2>() - truth.head<2>()).norm(), 0.005);
  EXPECT_LT(std::abs(wrap_angle_rad(estimate->pose_map_base.z() - truth.z())), 0.03);
  // Eq. 12: the heading's variance is the receivers' across the robot over (2 l)^2, twice: far
  // larger than the position's (0.133 m lever).
  EXPECT_GT(estimate->covariance(2, 2), estimate->covariance(0, 0));
}

TEST(TwoReceiverEkf, AnEchoLongerThanTheOtherReceiversRangeAllowsIsRefused) {
  const Pose2 truth(1.0, 1.2, 0.8);
  EstimatorConfig config = two_receivers();
  config.initial_pose = truth;
  auto e = on_the_map(config);
  StampNs t = 50 * kNsPerMillisecond;
  ASSERT_TRUE(e->predict(standing_odometry(t, 0.3, 1e-6)).accepted);
  const auto firing = [&](std::uint32_t id, StampNs stamp) {
    return test_support::exact_ranges(truth, config.receivers, *kMap.find(id), stamp);
  };
  // The receivers are 0.266 m apart: 0.5 m longer than the other's range cannot be direct.
  auto ranges = firing(1, t);
  ranges[1].range_m = ranges[0].range_m + 0.5;
  EXPECT_TRUE(e->update(ranges[0]).accepted);
  EXPECT_EQ(e->update(ranges[1]).rejection, Rejection::kEchoOfFiring);
  // An echo the separation could explain is left to the filter's gate; a firing 100 ms later is
  // another firing.
  ranges = firing(2, t + 1'000'000);
  ranges[1].range_m = ranges[0].range_m + 0.2;
  EXPECT_TRUE(e->update(ranges[0]).accepted);
  EXPECT_NE(e->update(ranges[1]).rejection, Rejection::kEchoOfFiring);
  ranges = firing(3, t + 2'000'000);
  EXPECT_TRUE(e->update(ranges[0]).accepted);
  auto later = firing(3, t + 100 * kNsPerMillisecond);
  later[1].range_m = ranges[0].range_m + 0.5;
  EXPECT_NE(e->update(later[1]).rejection, Rejection::kEchoOfFiring);
}

// Until a receiver's gate closes, a range much longer than predicted is fused down-weighted
// (open_gate_echo_sigma); such ranges do not count as agreeing, so a run of them cannot close the
// gate (the next would then be refused as gated rather than down-weighted).
TEST(TwoReceiverEkf, RangesDownWeightedAsEchoesDoNotCloseTheGate) {
  const Pose2 truth(1.0, 1.2, 0.8);
  EstimatorConfig config = two_receivers();
  config.initial_pose = truth;
  config.parameters = {{"initial_sigma_m", 0.05}};
  auto e = on_the_map(config);
  StampNs t = 0;
  for (int k = 0; k < 15; ++k) {  // more than gate_after_agreeing (10)
    t += 50 * kNsPerMillisecond;
    ASSERT_TRUE(e->predict(standing_odometry(t, 0.3, 1e-6)).accepted);
    RangeMeasurement front = test_support::exact_ranges(truth, config.receivers, *kMap.find(1 + k % 4), t)[0];
    front.range_m += 0.5;  // ten sigma of the innovation and more: down-weighted, not agreeing
    const InputResult u = e->update(front);
    EXPECT_TRUE(u.accepted) << "range " << k << ": " << (u.rejection ? to_string(*u.rejection) : "");
  }
}

// Ranges that put the front receiver 0.4 m from where the rear one and the mounting put it (a
// receiver's filter pulled onto a wrong solution): the pair contradicts the rigid robot, and the
// pose is degraded, not ok.
TEST(TwoReceiverEkf, ReceiversThatContradictTheMountingMakeThePoseDegraded) {
  const Pose2 truth(1.0, 1.2, 0.0);
  EstimatorConfig config = two_receivers();
  config.initial_pose = truth;
  auto e = on_the_map(config);
  ReceiverArray stretched = config.receivers;
  stretched.receivers_base_m[0] = {kL + 0.4, 0.0};
  StampNs t = 0;
  for (int cycle = 0; cycle < 40; ++cycle) {
    for (const Beacon& b : kMap.beacons()) {
      t += 50 * kNsPerMillisecond;
      ASSERT_TRUE(e->predict(standing_odometry(t, 0.3, 1e-6)).accepted);
      for (const RangeMeasurement& r : test_support::exact_ranges(truth, stretched, b, t)) e->update(r);
    }
  }
  ASSERT_TRUE(e->estimate());
  EXPECT_EQ(e->status(), PoseStatus::kDegraded);
}

}  // namespace
}  // namespace beaconloc
