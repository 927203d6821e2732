// range_ekf against the posterior Cramer-Rao bound (plugins/eval/offline/pose_bound.hpp, issue 18):
// the position and heading RMS over the seeds beside the bound's, on the four seed 000
// trajectories and on the seed 001 classroom with its ranges identified (the bound is given the
// association; range_ekf needs it). The ratios are printed; docs/bound.md has the table and the
// command that makes it:
//   beaconloc accuracy --scenario examples/scenarios/seed000_trajectoryN.yaml --seeds 10
//   beaconloc accuracy --scenario examples/scenarios/seed001_classroom.yaml --identified --seeds 30 --settle-s 15
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "offline_run.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc {
namespace {

struct Ratios {
  double position = 0.0;
  double heading = 0.0;
};

// Quadratic means over the seeds of ours and of the bound, and their ratios.
Ratios against_the_bound(const sim::Scenario& scenario, int seeds, double settle_s) {
  double ours_p = 0.0, ours_h = 0.0, bound_p = 0.0, bound_h = 0.0;
  for (int k = 1; k <= seeds; ++k) {
    const OfflineRunResult r = run_scenario_offline(scenario, static_cast<std::uint64_t>(k), "range_ekf", {}, settle_s);
    EXPECT_GT(r.metrics.samples, 0u) << scenario.name << " seed " << k;
    EXPECT_TRUE(r.bound.rms) << scenario.name << ": " << r.bound.unavailable;
    EXPECT_TRUE(r.metrics.heading_rms_deg);
    if (!r.bound.rms || !r.metrics.heading_rms_deg) return {};
    EXPECT_EQ(r.bound.rms->samples, r.metrics.samples);  // the same stamps
    ours_p += r.metrics.position_rms_m * r.metrics.position_rms_m;
    ours_h += *r.metrics.heading_rms_deg * *r.metrics.heading_rms_deg;
    bound_p += r.bound.rms->position_m * r.bound.rms->position_m;
    bound_h += r.bound.rms->heading_deg * r.bound.rms->heading_deg;
  }
  const Ratios out{std::sqrt(ours_p / bound_p), std::sqrt(ours_h / bound_h)};
  std::printf("%s, range_ekf, %d seeds from %.0f s: E_p RMS %.4f m, bound %.4f m (%.2fx); E_phi RMS %.3f deg, bound "
              "%.3f deg (%.2fx)\n",
              scenario.name.c_str(), seeds, settle_s, std::sqrt(ours_p / seeds), std::sqrt(bound_p / seeds),
              out.position, std::sqrt(ours_h / seeds), std::sqrt(bound_h / seeds), out.heading);
  return out;
}

sim::Scenario example(const std::string& name) {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/" + name + ".yaml");
}

// Issue 18: within 1.25x of the bound in position and in heading. Below 0.8x would say the bound
// is no bound (ten seeds estimate an RMS to about 10 %).
TEST(RangeEkfAgainstTheBound, Seed000TrajectoriesWithinAQuarterOfIt) {
  for (int t = 1; t <= 4; ++t) {
    const Ratios r = against_the_bound(example("seed000_trajectory" + std::to_string(t)), 10, 0.0);
    EXPECT_LE(r.position, 1.25) << "trajectory " << t;
    EXPECT_LE(r.heading, 1.25) << "trajectory " << t;
    EXPECT_GE(r.position, 0.8) << "trajectory " << t;
    EXPECT_GE(r.heading, 0.8) << "trajectory " << t;
  }
}

// The classroom's one receiver hears one beacon every 156 ms at sigma 0.4 m: range_ekf finds
// itself from the beacons (neither it nor its bound is told the start) and has no heading until the
// robot has moved, so the first 15 s (the first leg, 3.7 m, and its turn) are its start, not its
// tracking. Over those too it is 1.28x (position) and 2.11x (heading) the bound (docs/bound.md).
// Thirty seeds: the heading error wanders slowly, so a run is few independent samples of it.
TEST(RangeEkfAgainstTheBound, Seed001ClassroomWithinAQuarterOfItOnceStarted) {
  sim::Scenario classroom = example("seed001_classroom");
  classroom.identified = true;
  const Ratios tracking = against_the_bound(classroom, 30, 15.0);
  EXPECT_LE(tracking.position, 1.25);
  EXPECT_LE(tracking.heading, 1.25);
  EXPECT_GE(tracking.position, 0.8);
  EXPECT_GE(tracking.heading, 0.8);
  const Ratios from_start = against_the_bound(classroom, 30, 0.0);
  EXPECT_GT(from_start.heading, tracking.heading);  // the start is what costs
}

}  // namespace
}  // namespace beaconloc
