// scan on the seed 003 setup (examples/scenarios/seed003_scan.yaml): the LRULPSs' beacons as
// calibrated while driving, against the simulator's truth, and the robot's path in the map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <utility>
#include <string>
#include <vector>

#include "beaconloc/core/chi_square.hpp"
#include "beaconloc/core/decimal.hpp"
#include "offline_run.hpp"
#include "scan/scan_estimator.hpp"
#include "sim/scenario_yaml.hpp"
#include "svg_plot.hpp"

namespace beaconloc::scan {
namespace {

// The seed 003 scenario, or BEACONLOC_SEED003_SCENARIO's (a copy with one assumption changed, to
// see what the figures depend on: docs/accuracy-seed003.md).
sim::Scenario seed003() {
  if (const char* file = std::getenv("BEACONLOC_SEED003_SCENARIO")) return sim::load_scenario_file(file);
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed003_scan.yaml");
}

struct ScanRun {
  BeaconCalibration calibration;
  std::map<std::uint32_t, double> beacon_error_m;  // by beacon id
  std::map<std::uint32_t, double> group_mean_error_m;
  std::size_t beacons_outside_3_sigma = 0;  // error outside the covariance's 3-sigma ellipse
  double beacon_nees_sum = 0.0;              // e^T C^-1 e over the beacons (2 expected each)
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
  TofDecoder decoder = scenario_decoder(s);
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
      const Eigen::Vector2d error = b.position_map_m.head<2>() - truth.find(b.id)->position_map_m.head<2>();
      const double err = error.norm();
      // NEES over chi-square(2) 99.73 %: outside the 3-sigma ellipse.
      const double nees = error.dot(b.covariance_m2.ldlt().solve(error));
      out.beacons_outside_3_sigma += nees > kChiSquare2Dof3Sigma ? 1 : 0;
      out.beacon_nees_sum += nees;
      out.beacon_error_m[b.id] = err;
      sum += err;
    }
    out.group_mean_error_m[g.group] = sum / static_cast<double>(g.beacons.size());
  }
  return out;
}

// Runs per configuration: 4 in the suite (1 s); the paper's 100 with BEACONLOC_SEED003_RUNS=100
// (docs/accuracy-seed003.md).
constexpr int kPaperRuns = 100;  // seed 003 Figs. 13 and 15: "average errors after 100 iterations"
int runs() {
  const char* text = std::getenv("BEACONLOC_SEED003_RUNS");
  if (!text) return 4;
  std::int32_t n = 0;
  if (parse_decimal(text, n) != NumberError::kNone || n < 1 || n > 10000) {
    ADD_FAILURE() << "BEACONLOC_SEED003_RUNS must be a whole number in [1, 10000]";
    return 4;
  }
  return n;
}

// The q quantile (the sample at q of the way through the sorted values); NaN for none.
double quantile_of(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

// The locally referenced groups by their distance to the nearest globally referenced one
// (centre to centre), farthest first.
std::vector<std::uint32_t> local_groups_farthest_first(const sim::Scenario& s) {
  const auto centres = s.group_centres_map_m();
  std::vector<std::pair<double, std::uint32_t>> by_distance;
  for (const auto& [group, centre] : centres) {
    if (!s.local_group_frames_map.count(group)) continue;
    double nearest_m = INFINITY;
    for (const auto& [other, other_centre] : centres) {
      if (!s.local_group_frames_map.count(other)) nearest_m = std::min(nearest_m, (centre - other_centre).norm());
    }
    by_distance.push_back({nearest_m, group});
  }
  std::sort(by_distance.rbegin(), by_distance.rend());
  std::vector<std::uint32_t> out;
  for (const auto& [d, group] : by_distance) out.push_back(group);
  return out;
}

// Sec. 4.1-4.2 and Fig. 13: the beacons' calibration error over the runs, EKF, UKF and
// H-infinity side by side on the same runs (the same seeds), spherical and hyperbolic, with the
// analytic transform (d_min = 2.5 m) and the numerical one (Sec. 4.2: 20 points), and the
// inverse trajectory. Every LRULPS is calibrated on every run, in the order the robot meets
// them, with a covariance that owns its error (calibration_covariance.hpp; asserted below).
//
// Over the paper's 100 runs, the claims of the paper: the worst group is the one farthest from
// a GRULPS (LRULPS #4, group 6: 15.9 m; Sec. 2, and Sec. 4.1's "around the middle of the
// trajectory"), in every configuration; the means are under the paper's figures, < 0.2 m
// spherical and < 0.4 m hyperbolic with the analytic transform (Sec. 4.1; 100 runs:
// 0.135-0.158 m and 0.194-0.208 m), < 0.35 m hyperbolic with the numerical one (Sec. 4.2;
// 0.229-0.237 m). The numerical spherical mean misses the paper's < 0.15 m (0.182-0.200 m)
// and is held to 0.25 m, a regression guard. Over the suite's 4 runs the worst is one of the
// three farthest (groups 5-7), and every bound is a regression guard, about 1.25 times what
// the same code gives (4 runs: 0.095-0.099, 0.163-0.188, 0.162-0.167 and 0.223-0.234 m). The
// first and the last group, beside a GRULPS, within 0.12 m (100 runs: 0.015-0.027 m and
// 0.026-0.101 m: a few runs keep the forward drive's calibration of the last group).
// docs/accuracy-seed003.md has the tables.
struct MeanBounds {
  double paper_runs_m;  // over kPaperRuns runs or more
  double suite_m;       // over fewer
};
MeanBounds mean_bounds(bool numerical, bool hyperbolic) {
  if (numerical) return hyperbolic ? MeanBounds{0.35, 0.29} : MeanBounds{0.25, 0.21};
  return hyperbolic ? MeanBounds{0.40, 0.235} : MeanBounds{0.20, 0.125};
}

TEST(ScanOnSeed003, EveryGroupIsCalibratedAndTheWorstIsInTheMiddle) {
  const sim::Scenario s = seed003();
  const int n = runs();
  for (const double numerical : {0.0, 1.0}) {
  for (const double hyperbolic : {0.0, 1.0}) {
    for (const double filter : {0.0, 1.0, 2.0}) {
      std::map<std::uint32_t, std::vector<double>> by_group;  // each run's mean over the group's beacons
      std::vector<double> all;
      std::size_t outside_3_sigma = 0;
      double nees_sum = 0.0;
      for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(n); ++seed) {
        const ScanRun r = run(s, seed, {{"filter", filter}, {"hyperbolic", hyperbolic}, {"numerical_transform", numerical}});
        ASSERT_EQ(r.calibration.groups.size(), s.local_group_frames_map.size())
            << "seed " << seed << " filter " << filter << " hyperbolic " << hyperbolic;
        std::vector<std::uint32_t> order;
        for (const GroupCalibration& g : r.calibration.groups) order.push_back(g.group);
        EXPECT_TRUE(std::is_sorted(order.begin(), order.end()));  // groups 3..9 lie along the path in id order
        for (const auto& [g, e] : r.group_mean_error_m) by_group[g].push_back(e);
        for (const auto& [id, e] : r.beacon_error_m) all.push_back(e);
        outside_3_sigma += r.beacons_outside_3_sigma;
        nees_sum += r.beacon_nees_sum;
      }
      std::uint32_t worst = 0;
      double worst_mean = -1.0;
      std::printf("%s %s %s, %d runs: mean beacon error %.3f m; by group (mean/median):",
                  numerical > 0 ? "numerical" : "analytic", hyperbolic > 0 ? "hyperbolic" : "spherical",
                  to_string(static_cast<FilterKind>(static_cast<int>(filter))), n, mean_of(all));
      for (const auto& [g, errors] : by_group) {
        std::vector<double> sorted = errors;
        std::sort(sorted.begin(), sorted.end());
        std::printf(" %u: %.3f/%.3f", g, mean_of(errors), sorted[sorted.size() / 2]);
        if (mean_of(errors) > worst_mean) {
          worst_mean = mean_of(errors);
          worst = g;
        }
      }
      const double outside_share = static_cast<double>(outside_3_sigma) / static_cast<double>(all.size());
      const double mean_nees = nees_sum / static_cast<double>(all.size());
      std::printf("; worst %u; %.1f %% of beacons outside their 3-sigma ellipse, mean NEES %.2f (2 expected)\n",
                  worst, 100.0 * outside_share, mean_nees);
      const std::vector<std::uint32_t> farthest = local_groups_farthest_first(s);
      if (n >= kPaperRuns) {
        EXPECT_EQ(worst, farthest.front());
      } else {
        EXPECT_TRUE(std::find(farthest.begin(), farthest.begin() + 3, worst) != farthest.begin() + 3) << worst;
      }
      EXPECT_LT(mean_of(by_group.begin()->second), 0.12);   // LRULPS #1
      EXPECT_LT(mean_of(by_group.rbegin()->second), 0.12);  // LRULPS #7
      // The calibrations own their errors: few beacons outside their 3-sigma ellipse (0.27 % for
      // an exact covariance; 100 runs: 0-1.7 %, 4 runs: up to 3.6 %), and the covariance not
      // grossly larger than the errors (100 runs: mean NEES 0.52-1.82, 2 for an exact one).
      EXPECT_LT(outside_share, n >= kPaperRuns ? 0.05 : 0.10);
      if (n >= kPaperRuns) {
        EXPECT_GT(mean_nees, 0.25);
      }
      const MeanBounds bounds = mean_bounds(numerical > 0, hyperbolic > 0);
      EXPECT_LT(mean_of(all), n >= kPaperRuns ? bounds.paper_runs_m : bounds.suite_m);
    }
  }
  }
}

// Fig. 11: the CDF of every calibrated beacon's error for several d_min (analytic method,
// spherical, EKF). As in the paper, the middle value 2.5 m does best: 0.5 m and 1.5 m give
// worse transforms (two points close together; a larger mean), and 5 m, not much shorter than
// the 6 m over which the robot hears two consecutive groups (less the frame's start), calibrates
// only the groups whose two points happen to fit (100 runs: 142 of 700), with a longer tail (95 %
// quantile 1.85 m against 0.62 m). Groups left uncalibrated are counted and said.
// BEACONLOC_SEED003_CDF_SVG=FILE writes the plot.
TEST(ScanOnSeed003, CalibrationErrorCdfOverDmin) {
  const sim::Scenario s = seed003();
  const int n = runs();
  std::vector<CdfSeries> series;
  std::map<double, std::vector<double>> errors;
  std::map<double, std::size_t> groups_calibrated;
  for (const double d_min : {0.5, 1.5, 2.5, 5.0}) {
    std::size_t groups = 0;
    for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(n); ++seed) {
      const ScanRun r = run(s, seed, {{"d_min_m", d_min}});
      groups += r.calibration.groups.size();
      for (const auto& [id, e] : r.beacon_error_m) errors[d_min].push_back(e);
    }
    groups_calibrated[d_min] = groups;
    std::vector<double> sorted = errors[d_min];
    std::sort(sorted.begin(), sorted.end());
    const auto quantile = [&](double q) { return quantile_of(sorted, q); };
    std::printf("d_min %.1f m, %d runs: %zu of %zu groups calibrated; beacon error median %.3f m, 95 %% %.3f m, "
                "mean %.3f m\n",
                d_min, n, groups, static_cast<std::size_t>(n) * s.local_group_frames_map.size(), quantile(0.5),
                quantile(0.95), mean_of(sorted));
    char label[64];
    std::snprintf(label, sizeof label, "d_min = %.1f m (%zu beacons)", d_min, sorted.size());
    series.push_back({label, sorted});
  }
  // As Fig. 11: 2.5 m calibrates every group, and better than the lower and higher values.
  const std::size_t all_groups = static_cast<std::size_t>(n) * s.local_group_frames_map.size();
  EXPECT_EQ(groups_calibrated[2.5], all_groups);
  EXPECT_LT(mean_of(errors[2.5]), mean_of(errors[0.5]));
  EXPECT_LT(mean_of(errors[2.5]), mean_of(errors[1.5]));
  EXPECT_GT(groups_calibrated[5.0], 0u);
  EXPECT_LT(groups_calibrated[5.0], all_groups);
  EXPECT_GT(quantile_of(errors[5.0], 0.95), quantile_of(errors[2.5], 0.95));
  if (const char* svg = std::getenv("BEACONLOC_SEED003_CDF_SVG")) {
    write_cdf_svg(svg, "seed 003: beacon calibration error over d_min", "beacon position error (m)", series);
  }
}

}  // namespace
}  // namespace beaconloc::scan
