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
  const std::string table = accuracy_table_markdown({{"s", "e", {a, b}, {}, {}}});
  EXPECT_NE(table.find("| s | e | 2 | 0.050 +- 0.014 | 3.00 +- 1.41 | n/a | 0.80 +- 0.14 |"),
            std::string::npos)
      << table;
}

}  // namespace
}  // namespace beaconloc
