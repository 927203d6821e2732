// The localizer core: one estimator per robot on shared topics, robot filtering, counts.
#include "localizer_core.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "beaconloc/core/estimator_registry.hpp"
#include "offline_pipeline.hpp"

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

}  // namespace
}  // namespace beaconloc
