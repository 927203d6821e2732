// The duhl and uhl_last2 estimators: registered by name, refusing a robot without the receiver
// ring of seed 000 eq. 1; a Tx estimate its own measurement contradicts is discarded and started
// anew. (Their accuracy against Table II: duhl/accuracy/duhl_table2_test.cpp.)
#include "duhl/duhl_estimator.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "beaconloc/core/estimator_registry.hpp"
#include "exact_ranges.hpp"

namespace beaconloc {
namespace {

EstimatorConfig ring_config() {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
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
  StandingRobot() : duhl_(ring_config()) {
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
  void fire(std::uint32_t beacon_id, double error_on_receiver_0_m = 0.0) {
    std::vector<RangeMeasurement> ranges = test_support::exact_ranges(
        truth_, ReceiverArray::on_circle(0.19, 3), *map_.find(beacon_id), stamp_ns_);
    ranges[0].range_m += error_on_receiver_0_m;
    for (const RangeMeasurement& r : ranges) ASSERT_TRUE(duhl_.update(r).accepted);
  }
  duhl::Duhl duhl_;
  BeaconMap map_;
  Pose2 truth_{0.9, 0.5, 0.3};
  StampNs stamp_ns_ = 0;
};

TEST(DuhlEstimator, DiscardsATxEstimateItsOwnMeasurementContradictsAndStartsItAnew) {
  StandingRobot robot;
  for (int cycle = 0; cycle < 5; ++cycle) {
    for (std::uint32_t id = 1; id <= 3; ++id) {
      robot.fire(id);
      for (int k = 0; k < 20; ++k) robot.odometry();  // one 200 ms slot
    }
  }
  ASSERT_TRUE(robot.duhl_.estimate());
  EXPECT_LT((robot.duhl_.estimate()->pose_map_base.head<2>() - robot.truth_.head<2>()).norm(), 1e-3);
  EXPECT_EQ(robot.duhl_.available_txs(), 3u);
  EXPECT_EQ(robot.duhl_.contradicted_txs(), 0u);

  // 0.3 m off on one receiver (30 sigma): the Tx's estimate is dropped and re-made from the pose
  // before the measurement corrects it, so the estimate is not dragged along.
  robot.fire(2, 0.3);
  robot.odometry();
  EXPECT_EQ(robot.duhl_.contradicted_txs(), 1u);
  EXPECT_EQ(robot.duhl_.available_txs(), 3u);
  EXPECT_LT((robot.duhl_.estimate()->pose_map_base.head<2>() - robot.truth_.head<2>()).norm(), 0.05);
}

}  // namespace
}  // namespace beaconloc
