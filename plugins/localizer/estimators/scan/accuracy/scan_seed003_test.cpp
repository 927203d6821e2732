// scan on the seed 003 setup (examples/scenarios/seed003_scan.yaml): the LRULPSs' beacons as
// calibrated while driving, against the simulator's truth, and the robot's path in the map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "offline_run.hpp"
#include "scan/scan_estimator.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc::scan {
namespace {

sim::Scenario seed003() {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed003_scan.yaml");
}

struct ScanRun {
  BeaconCalibration calibration;
  std::map<std::uint32_t, double> beacon_error_m;  // by beacon id
  std::map<std::uint32_t, double> group_mean_error_m;
  double position_rms_m = 0.0;
  std::size_t poses = 0;
};

ScanRun run(const sim::Scenario& s, std::uint64_t seed, const std::map<std::string, double>& parameters,
            bool verbose = false) {
  EstimatorConfig config;
  config.receivers = s.receivers;
  config.parameters = parameters;
  ScanEstimator scan(config);
  const BeaconMap map(s.beacon_list());
  scan.set_beacon_map(map);
  TofDecoderConfig dc;
  dc.min_range_m = s.min_range_m;
  dc.max_range_m = s.max_range_m;
  dc.range_sigma_m = s.range_sigma_m;
  TofDecoder decoder(dc);
  decoder.set_beacon_map(map);
  ScanRun out;
  double sum2 = 0.0;
  double next_print_s = 0.0;
  for (const SourceEvent& e : simulate(s, seed, s.duration_s)) {
    const std::optional<EstimatorInput> input = estimator_input("robot", e, decoder, BeaconInput::kRanges);
    if (!input) continue;
    scan.push(*input);
    if (e.kind != SourceEvent::Kind::kOdometry || !e.has_truth) continue;
    const std::optional<PoseEstimate> est = scan.estimate();
    if (!est) continue;
    const double err = (est->pose_map_base.head<2>() - e.truth_map_base.head<2>()).norm();
    sum2 += err * err;
    ++out.poses;
    if (verbose && ns_to_s(e.stamp_ns) >= next_print_s) {  // for a person looking into a run
      std::printf("t %.1f truth %.2f %.2f est %.2f %.2f err %.3f sigma %.3f status %s calibrated %zu\n",
                  ns_to_s(e.stamp_ns), e.truth_map_base.x(), e.truth_map_base.y(), est->pose_map_base.x(),
                  est->pose_map_base.y(), err, std::sqrt(est->covariance.topLeftCorner<2, 2>().trace()),
                  to_string(est->status), scan.calibration().groups.size());
      for (std::uint32_t g = 3; g <= 4; ++g) {
        const auto pc = scan.provisional_calibration(g);
        if (pc) std::printf("   group %u provisional t_c %.3f %.3f %.3f %.3f err %.3f\n", g, pc->transform(0), pc->transform(1), pc->transform(2), pc->transform(3), pc->mean_error_m);
      }
      next_print_s += 5.0;
    }
  }
  scan.finish();  // the recording ends
  out.position_rms_m = out.poses ? std::sqrt(sum2 / static_cast<double>(out.poses)) : 0.0;
  out.calibration = scan.calibration();
  const BeaconMap truth(s.beacons);
  for (const GroupCalibration& g : out.calibration.groups) {
    double sum = 0.0;
    for (const CalibratedBeacon& b : g.beacons) {
      const double err = (b.position_map_m.head<2>() - truth.find(b.id)->position_map_m.head<2>()).norm();
      out.beacon_error_m[b.id] = err;
      sum += err;
    }
    out.group_mean_error_m[g.group] = sum / static_cast<double>(g.beacons.size());
  }
  return out;
}

// Where the calibration stands (issue 16 is open): every LRULPS is calibrated on every run, in the
// order the robot meets them, with EKF, UKF and H-infinity on ranges and on range differences; the
// first LRULPS (beside GRULPS 1) to a few centimetres. The chain's error grows from there: each
// link's rotation is off by about -0.04 rad on every seed (a bias, not noise; under
// investigation), and no inverse-trajectory pass corrects the last groups yet (Sec. 3.6), so the
// paper's < 0.2 m / < 0.4 m mean over all groups is NOT met: the table this prints says by how much.
TEST(ScanOnSeed003, EveryGroupIsCalibratedInTurnAndTheFirstToAFewCentimetres) {
  const sim::Scenario s = seed003();
  constexpr int kSeeds = 4;
  for (const double hyperbolic : {0.0, 1.0}) {
    for (const double filter : {0.0, 1.0, 2.0}) {
      std::map<std::uint32_t, double> mean_by_group;
      double all = 0.0;
      for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
        const ScanRun r = run(s, seed, {{"filter", filter}, {"hyperbolic", hyperbolic}});
        ASSERT_EQ(r.calibration.groups.size(), s.local_group_frames_map.size())
            << "seed " << seed << " filter " << filter << " hyperbolic " << hyperbolic;
        std::vector<std::uint32_t> order;
        for (const GroupCalibration& g : r.calibration.groups) order.push_back(g.group);
        EXPECT_TRUE(std::is_sorted(order.begin(), order.end()));  // groups 3..9 lie along the path in id order
        for (const auto& [g, e] : r.group_mean_error_m) {
          mean_by_group[g] += e / kSeeds;
          all += e / (kSeeds * static_cast<double>(r.group_mean_error_m.size()));
        }
        EXPECT_LT(r.group_mean_error_m.at(3), hyperbolic > 0 ? 0.15 : 0.10) << "seed " << seed;
      }
      std::printf("%s %s, %d seeds: mean beacon error %.3f m; by group:", hyperbolic > 0 ? "hyperbolic" : "spherical",
                  to_string(static_cast<FilterKind>(static_cast<int>(filter))), kSeeds, all);
      for (const auto& [g, e] : mean_by_group) std::printf(" %u: %.3f", g, e);
      std::printf("\n");
    }
  }
}

}  // namespace
}  // namespace beaconloc::scan
