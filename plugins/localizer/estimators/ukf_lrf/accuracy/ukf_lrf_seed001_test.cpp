// The seed 001 UKF on the classroom scenario over ten seeds, its three modes against the paper's
// Table 6 (fusion 0.101 m RMSE < LRF only 0.138 m < USAT only 0.245 m), and the association of
// the anonymous ranges against the simulator's truth (Tables 5 and 7: 77.0 % fused, 81.4 %
// USAT only). Then the classroom as the paper ran it, its map not fully known
// (seed001_classroom_unknown.yaml): the paper's filter without a beam gate against ours.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "offline_run.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc {
namespace {

struct ModeResult {
  double rmse_m = 0.0;
  double association_rate = 0.0;
  double beams_gated = 0.0;  // summed over the seeds (the estimator's state, as last published)
};

ModeResult mean_over_ten_seeds(const sim::Scenario& scenario, const std::string& estimator,
                               const std::vector<std::string>& parameters = {}) {
  ModeResult r;
  std::size_t associated = 0, correct = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const OfflineRunResult run = run_scenario_offline(scenario, seed, estimator, parameters);
    EXPECT_GT(run.metrics.samples, 0u) << estimator << " seed " << seed << ": no pose to score";
    r.rmse_m += run.metrics.position_rms_m / 10.0;
    for (const Estimator::StateValue& v : run.last_state) {
      if (v.name == "beams_gated") r.beams_gated += v.value;
    }
    associated += run.associations.total();
    correct += run.associations.correct();
  }
  r.association_rate = associated ? static_cast<double>(correct) / static_cast<double>(associated) : 0.0;
  return r;
}

sim::Scenario classroom(const std::string& name) {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/" + name + ".yaml");
}

// Table 6's cases 3, 5 and 4: fusion, laser only, beacons only.
std::array<ModeResult, 3> three_modes(const sim::Scenario& scenario) {
  return {mean_over_ten_seeds(scenario, "ukf_lrf"), mean_over_ten_seeds(scenario, "ukf_lrf_laser_only"),
          mean_over_ten_seeds(scenario, "ukf_lrf_beacons_only")};
}

// Table 6's order is fusion < laser only < beacons only. In simulation the laser sees exactly its
// map, and its 19 beams at 45 Hz carry about 2000 times the information of the four beacon
// ranges per 625 ms: fusion and laser only tie (docs/accuracy-seed001.md, the physics). What is
// asserted: adding the beacons never costs more than 2 % over laser only, both laser modes beat
// the beacons alone and are within Table 6, and the anonymous ranges are associated far above
// chance.
TEST(UkfLrfOnSeed001, LaserModesWithinTableSixFusionNoWorseThanLaserOnlyBothBeatBeaconsOnly) {
  const sim::Scenario scenario = classroom("seed001_classroom");
  const auto [fusion, laser, beacons] = three_modes(scenario);
  std::printf(
      "RMSE: fusion %.4f m, laser only %.4f m, beacons only %.4f m; association: fusion %.1f %%, "
      "beacons only %.1f %%\n",
      fusion.rmse_m, laser.rmse_m, beacons.rmse_m, 100 * fusion.association_rate,
      100 * beacons.association_rate);
  EXPECT_LE(fusion.rmse_m, 0.101);  // Table 6, case 3
  EXPECT_LE(laser.rmse_m, 0.138);   // Table 6, case 5
  EXPECT_LE(fusion.rmse_m, 1.02 * laser.rmse_m);
  EXPECT_LT(laser.rmse_m, beacons.rmse_m);
  EXPECT_LT(fusion.rmse_m, beacons.rmse_m);
  EXPECT_LE(beacons.rmse_m, 0.5);  // Table 6, case 4: 0.245 m; ours 1.4x (docs: the layout is reconstructed)
  // Four beacons: chance is 25 %. The paper: 77.0 % fused, 81.4 % USAT only.
  EXPECT_GT(fusion.association_rate, 0.6);
  EXPECT_GT(beacons.association_rate, 0.6);
}

// Seed 001's title: a "partially unknown" room. The room as built on a 2 cm grid against the
// 10 cm map, chairs and things the map lacks, five people walking, the LMS-511's own errors and
// mixed pixels (docs/accuracy-seed001.md, "The classroom the map does not fully know").
TEST(UkfLrfOnSeed001, InARoomTheMapDoesNotFullyKnowTheBeamGateKeepsTrackWhereThePapersFilterLosesIt) {
  const sim::Scenario scenario = classroom("seed001_classroom_unknown");
  const auto [fusion, laser, beacons] = three_modes(scenario);
  // The paper's eq. 16-21 fuse every beam: no gate.
  const ModeResult ungated = mean_over_ten_seeds(scenario, "ukf_lrf", {"beam_gate_sigma=0"});
  std::printf(
      "RMSE: fusion %.4f m, laser only %.4f m, beacons only %.4f m, fusion without the beam gate %.4f m; "
      "association: fusion %.1f %%, beacons only %.1f %%; beams gated over the seeds: fusion %.0f, laser only "
      "%.0f, without the gate %.0f\n",
      fusion.rmse_m, laser.rmse_m, beacons.rmse_m, ungated.rmse_m, 100 * fusion.association_rate,
      100 * beacons.association_rate, fusion.beams_gated, laser.beams_gated, ungated.beams_gated);
  EXPECT_EQ(ungated.beams_gated, 0.0);
  EXPECT_GT(fusion.beams_gated, 0.0);
  EXPECT_GT(laser.beams_gated, 0.0);
  EXPECT_GT(ungated.rmse_m, 10.0 * fusion.rmse_m);  // lost: short beams pull the pose through the furniture
  // Kept on track, the laser modes are left with the map's own error: its faces up to half a
  // cell (0.05 m) from the room's. Table 6: 0.101 (fusion), 0.138 (laser only), 0.245 m (beacons
  // only), each allowed 1.5x.
  EXPECT_LE(fusion.rmse_m, 0.05);
  EXPECT_LE(laser.rmse_m, 0.05);
  EXPECT_LE(beacons.rmse_m, 1.5 * 0.245);
  EXPECT_LE(fusion.rmse_m, 1.02 * laser.rmse_m);
  EXPECT_LT(laser.rmse_m, beacons.rmse_m);
  // Tables 5 and 7: 77.0 % fused, 81.4 % beacons only.
  for (const double rate : {fusion.association_rate, beacons.association_rate}) {
    EXPECT_GT(rate, 0.70);
    EXPECT_LT(rate, 0.85);
  }
}

}  // namespace
}  // namespace beaconloc
