// Scenario runs without DDS and the accuracy table over seeds.
#include "offline_run.hpp"

#include <gtest/gtest.h>

#include "sim/scenario.hpp"

namespace beaconloc {
namespace {

TEST(OfflineRun, ScoresTheBuiltInScenarioAgainstItsTruth) {
  sim::Scenario scenario = sim::default_scenario();
  scenario.duration_s = 20.0;
  const OfflineRunResult r = run_scenario_offline(scenario, 1, "range_ekf", {});
  EXPECT_GT(r.poses, 1800u);
  EXPECT_EQ(r.metrics.samples, r.poses);
  EXPECT_LT(r.metrics.position_rms_m, 0.05);
  ASSERT_TRUE(r.metrics.heading_rms_deg);
  // Settling time and parameters reach the run: fewer poses scored, a refused parameter throws.
  EXPECT_LT(run_scenario_offline(scenario, 1, "range_ekf", {"nis_gate=20"}, 5.0).metrics.samples,
            r.poses - 400);
  EXPECT_THROW(run_scenario_offline(scenario, 1, "range_ekf", {"nis_gate"}), std::invalid_argument);
}

TEST(OfflineRun, TableGivesMeanAndSpreadOverSeeds) {
  Metrics a, b;
  a.position_rms_m = 0.04;
  b.position_rms_m = 0.06;
  a.heading_rms_deg = 2.0;
  b.heading_rms_deg = 4.0;
  a.nees_in_band_fraction = 0.9;
  b.nees_in_band_fraction = 0.7;
  const std::string table = accuracy_table_markdown({{"s", "e", {a, b}, {}, {}, {}, {}, false}});
  EXPECT_NE(table.find("| s | e | 2 | 0.050 +- 0.014 | 3.00 +- 1.41 | n/a | 0.80 +- 0.14 |"),
            std::string::npos)
      << table;
}

// Beside the bound: quadratic means over the seeds and their ratio; a laser user gets no ratio,
// a scenario the bound does not follow says why.
TEST(OfflineRun, BoundTableGivesQuadraticMeansAndRatios) {
  Metrics a, b;
  a.position_rms_m = 0.03;
  b.position_rms_m = 0.04;  // quadratic mean sqrt(0.00125) = 0.0354
  a.heading_rms_deg = 1.0;
  b.heading_rms_deg = 1.0;
  a.samples = b.samples = 10;  // the poses the bound covers
  const std::vector<PoseBoundRms> bounds{{0.025, 0.5, 10}, {0.025, 0.5, 10}};
  const std::vector<PoseBoundRms> other_poses{{0.025, 0.5, 10}, {0.025, 0.5, 9}};
  const std::string table = bound_table_markdown({{"s", "e", {a, b}, {}, {}, bounds, {}, false},
                                                  {"s", "l", {a, b}, {}, {}, bounds, {}, true},
                                                  {"t", "e", {a}, {}, {}, {}, "a reason", false},
                                                  {"u", "e", {a, b}, {}, {}, other_poses, {}, false}});
  EXPECT_NE(table.find("| s | e | 2 | 0.0354 | 0.0250 | 1.41x | 1.000 | 0.500 | 2.00x |"), std::string::npos) << table;
  EXPECT_NE(table.find("| s | l | 2 | 0.0354 | 0.0250 | n/a (fuses the laser"), std::string::npos) << table;
  EXPECT_NE(table.find("| t | e | 1 | n/a | n/a: a reason |"), std::string::npos) << table;
  EXPECT_NE(table.find("| u | e | 2 | 0.0354 | 0.0250 | n/a (the bound covers other poses"), std::string::npos) << table;
}

TEST(OfflineRun, GivesTheBoundOverTheStampsScored) {
  sim::Scenario scenario = sim::default_scenario();
  scenario.duration_s = 20.0;
  const OfflineRunResult r = run_scenario_offline(scenario, 1, "range_ekf", {}, 5.0);
  ASSERT_TRUE(r.bound.rms) << r.bound.unavailable;
  EXPECT_EQ(r.bound.rms->samples, r.metrics.samples);
  EXPECT_FALSE(r.bound.laser_fused);
  // range_ekf is near the bound here (docs/bound.md), and no estimator is far below it on a run.
  EXPECT_GT(r.metrics.position_rms_m, 0.8 * r.bound.rms->position_m);
  EXPECT_LT(r.metrics.position_rms_m, 1.5 * r.bound.rms->position_m);
  scenario.wheel_base_error = 0.01;
  EXPECT_NE(run_scenario_offline(scenario, 1, "range_ekf", {}, 5.0).bound.unavailable.find("wheel"),
            std::string::npos);
}

}  // namespace
}  // namespace beaconloc
