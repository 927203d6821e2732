// The duhl and uhl_last2 estimators: registered by name, refusing a robot without the receiver
// ring of seed 000 eq. 1; a Tx estimate its own measurement contradicts is discarded and started
// anew; echoes are refused against the pose, a robot that lost track finds it again, a start
// waits for distances that agree. (Their accuracy against Table II:
// duhl/accuracy/duhl_table2_test.cpp; under echoes: tests/accuracy/echoes_test.cpp.)
#include "duhl/duhl_estimator.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "beaconloc/core/estimator_registry.hpp"
#include "exact_ranges.hpp"

namespace beaconloc {
namespace {

EstimatorConfig ring_config(const std::map<std::string, double>& parameters = {}) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  config.parameters = parameters;
  return config;
}

TEST(DuhlEstimator, IsRegisteredAndRefusesARobotWithoutTheReceiverRing) {
  EXPECT_EQ(EstimatorRegistry::instance().create("duhl", ring_config())->name(), "duhl");
  EXPECT_EQ(EstimatorRegistry::instance().create("uhl_last2", ring_config())->name(), "uhl_last2");
  EstimatorConfig one;
  one.receivers.receivers_base_m = {{0.0, 0.0}};
  EXPECT_THROW(EstimatorRegistry::instance().create("duhl", one), std::invalid_argument);
}

// A robot standing still under three Txs, fed exact distances each firing slot.
class StandingRobot {
 public:
  explicit StandingRobot(const std::map<std::string, double>& parameters = {}) : duhl_(ring_config(parameters)) {
    map_ = BeaconMap({{1, {0.0, 0.0, 2.0}}, {2, {2.0, 0.0, 2.0}}, {3, {1.0, 1.5, 2.0}}});
    duhl_.set_beacon_map(map_);
  }
  void odometry() {
    stamp_ns_ += 10'000'000;
    OdometrySample o;
    o.stamp_ns = stamp_ns_;
    o.wheel_base_m = 0.33;
    ASSERT_TRUE(duhl_.predict(o).accepted);
  }
  // The results of the three receivers' ranges, receiver 0's error_on_receiver_0_m long.
  std::vector<InputResult> fire(std::uint32_t beacon_id, double error_on_receiver_0_m = 0.0) {
    std::vector<RangeMeasurement> ranges = test_support::exact_ranges(
        truth_, ReceiverArray::on_circle(0.19, 3), *map_.find(beacon_id), stamp_ns_);
    ranges[0].range_m += error_on_receiver_0_m;
    std::vector<InputResult> results;
    for (const RangeMeasurement& r : ranges) results.push_back(duhl_.update(r));
    return results;
  }
  void slot() {  // one 200 ms slot of odometry
    for (int k = 0; k < 20; ++k) odometry();
  }
  void cycles(int n) {
    for (int cycle = 0; cycle < n; ++cycle) {
      for (std::uint32_t id = 1; id <= 3; ++id) {
        fire(id);
        slot();
      }
    }
  }
  double position_error_m() const {
    return (duhl_.estimate()->pose_map_base.head<2>() - truth_.head<2>()).norm();
  }
  duhl::Duhl duhl_;
  BeaconMap map_;
  Pose2 truth_{0.9, 0.5, 0.3};
  StampNs stamp_ns_ = 0;
};

TEST(DuhlEstimator, DiscardsATxEstimateItsOwnMeasurementContradictsAndStartsItAnew) {
  // The pose's own gate off: the error below stands for a Tx estimate that drifted from a pose
  // that agrees with the measurement (a fast turn), which the pose gate lets through.
  StandingRobot robot({{"range_pose_gate", 0.0}});
  robot.cycles(5);
  ASSERT_TRUE(robot.duhl_.estimate());
  EXPECT_LT(robot.position_error_m(), 1e-3);
  EXPECT_EQ(robot.duhl_.available_txs(), 3u);
  EXPECT_EQ(robot.duhl_.contradicted_txs(), 0u);

  // 0.3 m off on one receiver (30 sigma): the Tx's estimate is dropped and re-made from the pose
  // before the measurement corrects it, so the estimate is not dragged along.
  for (const InputResult& r : robot.fire(2, 0.3)) EXPECT_TRUE(r.accepted);
  robot.odometry();
  EXPECT_EQ(robot.duhl_.contradicted_txs(), 1u);
  EXPECT_EQ(robot.duhl_.available_txs(), 3u);
  EXPECT_LT(robot.position_error_m(), 0.05);
}

TEST(DuhlEstimator, RefusesAnEchoThePoseCannotExplain) {
  StandingRobot robot;
  robot.cycles(5);
  ASSERT_TRUE(robot.duhl_.estimate());
  const std::vector<InputResult> results = robot.fire(2, 0.3);  // an echo's 0.3 m of extra path
  ASSERT_FALSE(results[0].accepted);
  EXPECT_EQ(results[0].rejection, Rejection::kGatedNis);
  EXPECT_TRUE(results[1].accepted);
  EXPECT_TRUE(results[2].accepted);
  robot.slot();
  EXPECT_EQ(robot.duhl_.contradicted_txs(), 0u);
  EXPECT_LT(robot.position_error_m(), 1e-3);
}

TEST(DuhlEstimator, ARobotCarriedAwayLosesItsPoseAndFindsItAgainFromTheBeacons) {
  StandingRobot robot;
  robot.cycles(5);
  ASSERT_TRUE(robot.duhl_.estimate());
  robot.truth_ = Pose2(1.4, 0.2, -0.5);  // carried 0.9 m without odometry
  const duhl::DuhlParameters defaults = duhl::DuhlParameters::from(ring_config());
  int gated = 0;
  while (robot.duhl_.estimate() && gated < 100) {
    for (std::uint32_t id = 1; id <= 3 && robot.duhl_.estimate(); ++id) {
      for (const InputResult& r : robot.fire(id)) gated += r.rejection == Rejection::kGatedNis ? 1 : 0;
      robot.slot();
      // Never ok once the ranges refuse it: degraded, then dropped.
      if (robot.duhl_.estimate() && gated >= defaults.suspect_after_gated_ranges) {
        EXPECT_EQ(robot.duhl_.estimate()->status, PoseStatus::kDegraded) << gated;
      }
    }
  }
  EXPECT_EQ(gated, defaults.lost_after_gated_ranges);
  EXPECT_FALSE(robot.duhl_.estimate());  // the pose is dropped, not kept wrong
  robot.cycles(2);
  ASSERT_TRUE(robot.duhl_.estimate());
  EXPECT_LT(robot.position_error_m(), 1e-3);
}

TEST(DuhlEstimator, DoesNotStartFromAUhlPoseAnEchoContradicts) {
  StandingRobot robot;
  robot.fire(1);
  robot.slot();
  robot.fire(2, 0.5);  // an echo on one receiver of the second Tx
  robot.slot();
  // Two Txs that disagree: which one is wrong cannot be told, both are measured again.
  EXPECT_FALSE(robot.duhl_.estimate());
  EXPECT_EQ(robot.duhl_.available_txs(), 0u);
  EXPECT_EQ(robot.duhl_.startup_wait()->condition, StartupCondition::kTooFewBeacons);
  robot.fire(3);
  robot.slot();
  robot.fire(1);
  robot.slot();
  ASSERT_TRUE(robot.duhl_.estimate());
  EXPECT_LT(robot.position_error_m(), 1e-3);
}

TEST(UhlLast2, RefusesTheRangeThatCompletesAnImpossibleFiringAndPassesTheFiringOver) {
  auto e = EstimatorRegistry::instance().create("uhl_last2", ring_config());
  const BeaconMap map({{1, {0.0, 0.0, 2.0}}, {2, {2.0, 0.0, 2.0}}, {3, {1.0, 1.5, 2.0}}});
  e->set_beacon_map(map);
  const Pose2 truth(0.9, 0.5, 0.3);
  StampNs t = 0;
  const auto fire = [&](std::uint32_t id, double echo_on_receiver_2_m) {
    std::vector<RangeMeasurement> ranges =
        test_support::exact_ranges(truth, ReceiverArray::on_circle(0.19, 3), *map.find(id), t);
    ranges[2].range_m += echo_on_receiver_2_m;
    std::vector<InputResult> out;
    for (const RangeMeasurement& r : ranges) out.push_back(e->update(r));
    OdometrySample o;
    t += 200'000'000;
    o.stamp_ns = t;
    o.wheel_base_m = 0.33;
    e->predict(o);
    return out;
  };
  fire(1, 0.0);
  const std::vector<InputResult> echoed = fire(2, 0.8);
  EXPECT_TRUE(echoed[0].accepted);
  EXPECT_TRUE(echoed[1].accepted);
  EXPECT_EQ(echoed[2].rejection, Rejection::kEchoOfFiring);
  EXPECT_FALSE(e->estimate());  // the pair is Tx 1 and a firing it passes over: not two Txs yet
  fire(3, 0.0);
  ASSERT_TRUE(e->estimate());
  EXPECT_LT((e->estimate()->pose_map_base.head<2>() - truth.head<2>()).norm(), 1e-3);
}

TEST(DuhlDistances, AFiringsDistancesMustBePossibleForTheRing) {
  const duhl::ReceiverRing ring;
  const BeaconMap map({{1, {0.3, -0.4, 2.0}}});
  const std::vector<RangeMeasurement> exact =
      test_support::exact_ranges(Pose2(0.0, 0.0, 0.2), ReceiverArray::on_circle(0.19, 3), *map.find(1), 0);
  duhl::Distances d(exact[0].range_m, exact[1].range_m, exact[2].range_m);
  EXPECT_TRUE(duhl::possible_distances(d, 1e-4, ring));
  d(1) += 0.5;  // further from the Tx than the other receivers' distances allow
  EXPECT_FALSE(duhl::possible_distances(d, 1e-4, ring));
  d(1) = std::nan("");
  EXPECT_FALSE(duhl::possible_distances(d, 1e-4, ring));
}

}  // namespace
}  // namespace beaconloc
