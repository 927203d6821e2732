// The localizer core: one estimator per robot on shared topics, robot filtering, counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "beaconloc/core/estimator_registry.hpp"
#include "localizer_core.hpp"
#include "sim/sim_source.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {
namespace {

TEST(LocalizerCore, UnknownEstimatorFailsAtConstruction) {
  EXPECT_THROW(LocalizerCore("nope", EstimatorConfig{}), UnknownEstimator);
}

TEST(LocalizerCore, KeepsRobotsApartOnSharedTopics) {
  // Two robots on the same path 7 s apart in time; each must be tracked by its own estimator.
  const sim::Scenario scenario = sim::default_scenario();
  EstimatorConfig config;
  config.receivers = scenario.receivers;
  LocalizerCore core("range_ekf", config);
  core.set_beacon_map(BeaconMap(scenario.beacons));
  TofDecoder decoder;
  decoder.set_beacon_map(BeaconMap(scenario.beacons));
  sim::SimSource a(scenario, 1), b(scenario, 2);
  std::vector<sim::SimEvent> ea, eb;
  a.advance(s_to_ns(20.0), ea);
  b.advance(s_to_ns(27.0), eb);
  eb.erase(eb.begin(), std::find_if(eb.begin(), eb.end(), [](const auto& e) { return e.stamp_ns > s_to_ns(7.0); }));
  double worst = 0.0;
  std::set<std::uint32_t> used;
  auto feed = [&](const std::string& robot, const sim::SimEvent& e) {
    if (e.kind == sim::SimEvent::Kind::kTof) {
      if (auto out = decoder.decode(robot, e.tof); out.range) core.on_range(robot, out.range->range);
      return;
    }
    if (auto pose = core.on_odometry(robot, e.odometry)) {
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
  EXPECT_EQ(core.robot_count(), 2u);
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
