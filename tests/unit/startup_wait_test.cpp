// Why an estimator has no pose yet: each estimator names the start-up condition it waits for
// with the numbers that matter, and the localizer core sums them up over its robots for the
// Diagnostics message.
#include <gtest/gtest.h>

#include <string>

#include "beaconloc/core/estimator_registry.hpp"
#include "exact_ranges.hpp"
#include "localizer_core.hpp"
#include "standing_robot.hpp"

namespace beaconloc {
namespace {

const BeaconMap kMap({{1, {0.0, 0.0, 2.0}, 0}, {2, {2.0, 0.0, 2.0}, 0}, {3, {1.0, 1.5, 2.0}, 0}});
const Pose2 kTruth(0.9, 0.5, 0.3);

// Drives one estimator of a robot standing at kTruth: odometry every 10 ms, the beacons given
// firing in turn every 200 ms, heard by every receiver.
class Standing {
 public:
  Standing(const std::string& estimator, std::map<std::string, double> parameters = {},
           ReceiverArray receivers = ReceiverArray::on_circle(0.19, 3))
      : receivers_(receivers) {
    EstimatorConfig config;
    config.receivers = receivers_;
    config.parameters = std::move(parameters);
    e_ = EstimatorRegistry::instance().create(estimator, config);
  }
  void slots(int n, std::vector<std::uint32_t> beacons, bool odometry = true) {
    for (int k = 0; k < n; ++k) {
      test_support::standing_slot(*e_, kTruth, receivers_,
                                  *kMap.find(beacons[static_cast<std::size_t>(k) % beacons.size()]),
                                  stamp_ns_, odometry);
    }
  }
  StartupCondition condition() const {
    const auto wait = e_->startup_wait();
    return wait ? wait->condition : static_cast<StartupCondition>(-1);
  }
  std::string describe() const { return e_->startup_wait() ? e_->startup_wait()->describe() : "has a pose"; }
  ReceiverArray receivers_;
  std::unique_ptr<Estimator> e_;
  StampNs stamp_ns_ = 0;
};

TEST(StartupWait, RangeEkfNamesWhatItWaitsFor) {
  Standing no_map("range_ekf");
  EXPECT_EQ(no_map.condition(), StartupCondition::kNoBeaconMap);
  EXPECT_EQ(no_map.describe(), "no beacon map");

  Standing two("range_ekf");
  two.e_->set_beacon_map(kMap);
  EXPECT_EQ(two.describe(), "0 of 3 beacons heard");
  two.slots(10, {1, 2});
  EXPECT_EQ(two.condition(), StartupCondition::kTooFewBeacons);
  EXPECT_EQ(two.describe(), "2 of 3 beacons heard");

  Standing few("range_ekf", {{"init_min_ranges", 20.0}});
  few.e_->set_beacon_map(kMap);
  few.slots(3, {1, 2, 3});
  EXPECT_EQ(few.condition(), StartupCondition::kTooFewRanges);
  EXPECT_EQ(few.describe(), "9 of 20 ranges");

  Standing uncertain("range_ekf", {{"init_max_position_sigma_m", 1e-4}, {"init_max_position_sigma_ranges", 0.0}});
  uncertain.e_->set_beacon_map(kMap);
  uncertain.slots(3, {1, 2, 3});
  EXPECT_EQ(uncertain.condition(), StartupCondition::kPositionTooUncertain) << uncertain.describe();
  EXPECT_NE(uncertain.describe().find("fix too uncertain: position sigma "), std::string::npos);
  EXPECT_GT(uncertain.e_->startup_wait()->value, uncertain.e_->startup_wait()->limit);

  // One receiver standing still: its heading is not in the ranges.
  ReceiverArray one;
  one.receivers_base_m = {{0.0, 0.0}};
  Standing still("range_ekf", {}, one);
  still.e_->set_beacon_map(kMap);
  still.slots(9, {1, 2, 3});
  EXPECT_EQ(still.condition(), StartupCondition::kFixFailed);
  EXPECT_EQ(still.describe(), "no global fix (unobservable)");

  // A global fix from ranges alone, but no odometry to stamp a pose with.
  Standing no_odometry("range_ekf");
  no_odometry.e_->set_beacon_map(kMap);
  no_odometry.slots(3, {1, 2, 3}, false);
  EXPECT_EQ(no_odometry.condition(), StartupCondition::kNoOdometry);

  Standing fine("range_ekf");
  fine.e_->set_beacon_map(kMap);
  fine.slots(3, {1, 2, 3});
  ASSERT_TRUE(fine.e_->estimate());
  EXPECT_FALSE(fine.e_->startup_wait());
}

TEST(StartupWait, DuhlAndUhlLast2NameWhatTheyWaitFor) {
  for (const char* name : {"duhl", "uhl_last2"}) {
    Standing s(name);
    EXPECT_EQ(s.condition(), StartupCondition::kNoBeaconMap) << name;
    s.e_->set_beacon_map(kMap);
    EXPECT_EQ(s.condition(), StartupCondition::kNoOdometry) << name;
    s.slots(3, {1});  // one Tx only
    EXPECT_EQ(s.condition(), StartupCondition::kTooFewBeacons) << name;
    EXPECT_EQ(s.e_->startup_wait()->value, 1.0) << name;
    EXPECT_EQ(s.e_->startup_wait()->limit, 2.0) << name;
    s.slots(3, {2, 3});
    ASSERT_TRUE(s.e_->estimate()) << name << ": " << s.describe();
    EXPECT_FALSE(s.e_->startup_wait()) << name;
  }
  Standing last2("uhl_last2");
  last2.e_->set_beacon_map(kMap);
  last2.slots(1, {1});
  EXPECT_EQ(last2.describe(), "1 of 2 beacons heard (heard by all three receivers)");
}

TEST(StartupWait, UkfLrfNeedsItsInitialPose) {
  EstimatorConfig config;
  config.receivers.receivers_base_m = {{0.0, 0.0}};
  auto unplaced = EstimatorRegistry::instance().create("ukf_lrf_beacons_only", config);
  ASSERT_TRUE(unplaced->startup_wait());
  EXPECT_EQ(unplaced->startup_wait()->condition, StartupCondition::kNeedsInitialPose);
  EXPECT_EQ(unplaced->startup_wait()->describe(), "needs an initial pose (--initial-pose or initial_pose)");
  config.initial_pose = kTruth;
  auto placed = EstimatorRegistry::instance().create("ukf_lrf_beacons_only", config);
  EXPECT_EQ(placed->startup_wait()->condition, StartupCondition::kNoOdometry);
  OdometrySample o;
  o.wheel_base_m = 0.4;
  ASSERT_TRUE(placed->predict(o).accepted);
  EXPECT_FALSE(placed->startup_wait());
}

TEST(StartupWait, TheLocalizerCountsItsRobotsPerConditionAndDetailsTheFirst) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  LocalizerCore core("range_ekf", config);
  OdometrySample o;
  o.wheel_base_m = 0.33;
  core.on_odometry("c", o);
  EXPECT_EQ(core.startup_summary().describe(), "1 initializing: no_beacon_map 1 (robot c: no beacon map)");
  core.set_beacon_map(kMap);
  for (const char* robot : {"b", "a", "ok"}) core.on_odometry(robot, o);
  for (int slot = 0; slot < 3; ++slot) {
    const StampNs t = (slot + 1) * 200'000'000;
    for (const char* robot : {"a", "ok"}) {
      if (std::string(robot) == "a" && slot == 2) continue;  // a hears two beacons
      for (const auto& r : test_support::exact_ranges(kTruth, config.receivers,
                                                      *kMap.find(static_cast<std::uint32_t>(slot + 1)), t)) {
        core.on_range(robot, r);
      }
    }
    OdometrySample later = o;
    later.stamp_ns = t + 10'000'000;
    for (const char* robot : {"a", "b", "c", "ok"}) core.on_odometry(robot, later);
  }
  EXPECT_FALSE(core.startup_wait("ok"));
  EXPECT_FALSE(core.startup_wait("nobody"));
  const StartupSummary s = core.startup_summary();
  EXPECT_EQ(s.robots_by_condition.at(StartupCondition::kTooFewBeacons), 3u);
  EXPECT_EQ(s.first_robot, "a");
  EXPECT_EQ(s.describe(), "3 initializing: too_few_beacons 3 (robot a: 2 of 3 beacons heard)");
  EXPECT_TRUE(LocalizerCore("range_ekf", config).startup_summary().empty());  // no robot yet
}

TEST(StartupWait, ConditionsHaveStableNames) {
  EXPECT_STREQ(to_string(StartupCondition::kMirrorAmbiguous), "mirror_ambiguous");
  EXPECT_STREQ(to_string(StartupCondition::kTooFewBeacons), "too_few_beacons");
  EXPECT_STREQ(to_string(StartupCondition::kNeedsInitialPose), "needs_initial_pose");
  EXPECT_EQ((StartupWait{StartupCondition::kPositionTooUncertain, 0.52, 0.3, {}}.describe()),
            "fix too uncertain: position sigma 0.52 m > 0.30 m");
  EXPECT_EQ((StartupWait{StartupCondition::kMirrorAmbiguous, 2.5, 10.83, {}}.describe()),
            "beacons on one line, mirror image fits as well (chi-square margin 2.5 < 10.8)");
}

}  // namespace
}  // namespace beaconloc
