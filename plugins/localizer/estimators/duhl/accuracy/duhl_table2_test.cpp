// DUHL on the four seed 000 trajectories over ten seeds, against the paper's Table II (release
// builds only: about 6 s there, a minute a trajectory in Debug).
#include <gtest/gtest.h>

#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "offline_run.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc {
namespace {

// Seed 000 Table II, DUHL: E_p RMS (m) and E_phi RMS (deg) for trajectories 1-4.
struct TableTwoRow {
  const char* scenario;
  double position_rms_m;
  double heading_rms_deg;
};

void PrintTo(const TableTwoRow& row, std::ostream* os) { *os << row.scenario; }

class DuhlOnSeed000 : public ::testing::TestWithParam<TableTwoRow> {};

double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

// Ten seeds of each trajectory through the decoder and localizer cores. duhl must meet Table II
// in position, beat the paper's baseline in position and heading, and report an honest
// covariance. Its heading is held to the information in the simulated data instead of Table II:
// under the paper's own odometry noise (k_v = 4e-4 m) the per-range EKF (range_ekf), with a
// consistent covariance, gets 2.1-3.0 deg on the same seeds, above Table II's 1.61-2.59 deg
// (docs/accuracy-seed000.md: the physics); duhl, which reuses each Tx's distances over the
// corrections until it is heard again, must stay within 1.75x of that.
TEST_P(DuhlOnSeed000, MeetsTableTwoInPositionWithAnHonestCovarianceAndBeatsTheLastTwoTxs) {
  const TableTwoRow row = GetParam();
  const sim::Scenario scenario = sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) +
                                                         "/examples/scenarios/" + row.scenario + ".yaml");
  std::vector<double> duhl_p, duhl_phi, duhl_nees, last2_p, last2_phi, ekf_phi;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const Metrics duhl = run_scenario_offline(scenario, seed, "duhl", {}).metrics;
    const Metrics last2 = run_scenario_offline(scenario, seed, "uhl_last2", {}).metrics;
    const Metrics ekf = run_scenario_offline(scenario, seed, "range_ekf", {}).metrics;
    ASSERT_TRUE(duhl.heading_rms_deg && last2.heading_rms_deg && ekf.heading_rms_deg);
    duhl_p.push_back(duhl.position_rms_m);
    duhl_phi.push_back(*duhl.heading_rms_deg);
    duhl_nees.push_back(duhl.nees_in_band_fraction);
    last2_p.push_back(last2.position_rms_m);
    last2_phi.push_back(*last2.heading_rms_deg);
    ekf_phi.push_back(*ekf.heading_rms_deg);
  }
  EXPECT_LE(mean_of(duhl_p), row.position_rms_m);
  EXPECT_GE(mean_of(duhl_nees), 0.80);
  EXPECT_GT(mean_of(last2_p), mean_of(duhl_p));
  EXPECT_GT(mean_of(last2_phi), mean_of(duhl_phi));
  EXPECT_LE(mean_of(duhl_phi), 1.75 * mean_of(ekf_phi));
  std::printf(
      "%s: duhl E_p %.3f m (Table II %.3f), E_phi %.2f deg (Table II %.2f, range_ekf %.2f), "
      "NEES in band %.2f; uhl_last2 E_p %.3f m, E_phi %.2f deg\n",
      row.scenario, mean_of(duhl_p), row.position_rms_m, mean_of(duhl_phi), row.heading_rms_deg,
      mean_of(ekf_phi), mean_of(duhl_nees), mean_of(last2_p), mean_of(last2_phi));
}

INSTANTIATE_TEST_SUITE_P(TableTwo, DuhlOnSeed000,
                         ::testing::Values(TableTwoRow{"seed000_trajectory1", 0.070, 1.61},
                                           TableTwoRow{"seed000_trajectory2", 0.063, 2.20},
                                           TableTwoRow{"seed000_trajectory3", 0.081, 1.98},
                                           TableTwoRow{"seed000_trajectory4", 0.104, 2.59}),
                         [](const ::testing::TestParamInfo<TableTwoRow>& row_info) {
                           return std::string(row_info.param.scenario);
                         });

}  // namespace
}  // namespace beaconloc
