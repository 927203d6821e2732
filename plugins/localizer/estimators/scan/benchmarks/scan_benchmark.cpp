// Cost of seed 003's filters (scan/frame_filter.hpp) per update, EKF, UKF and H-infinity side by
// side (Sec. 3.4), on the state and covariance the global frame had 30 s into the seed 003 run:
//  - BM_ScanFrame_Range/<filter>: one range (spherical, eq. 26 with eq. 18);
//  - BM_ScanFrame_Differences/<filter>: one epoch of a four-beacon group (hyperbolic, eq. 27 with
//    eq. 19), the ranges moved to the epoch's end first;
//  - BM_Scan_InverseTrajectory: the backwards drive (Sec. 3.6) over the whole seed 003 drive.
// Each iteration updates a copy of the frame (a few hundred bytes: its cost is in the figure).
// The paper gives no cost.
#include <benchmark/benchmark.h>

#include "estimator_bench.hpp"
#include "scan/frame_filter.hpp"
#include "scan/inverse_trajectory.hpp"

namespace beaconloc {
namespace {

constexpr scan::FilterKind kKinds[] = {scan::FilterKind::kEkf, scan::FilterKind::kUkf, scan::FilterKind::kHInfinity};

// The global frame's belief at 30 s on the seed 003 drive (inside LRULPS #3's coverage).
scan::FrameFilter frame_of(scan::FilterKind kind) {
  scan::FrameFilterSettings settings;
  settings.kind = kind;
  scan::FrameFilter f(settings);
  Cov3 p;
  p << 4e-4, 1e-5, 2e-5, 1e-5, 9e-4, 1e-4, 2e-5, 1e-4, 4e-3;
  f.start(Pose2(13.8, 2.0, 0.01), p);
  return f;
}

const Eigen::Vector3d kBeacons[] = {{12.35, 2.35, 3.5}, {11.65, 2.35, 3.5}, {11.65, 1.65, 3.5}, {12.35, 1.65, 3.5}};

void BM_ScanFrame_Range(benchmark::State& state) {
  const scan::FrameFilter base = frame_of(kKinds[state.range(0)]);
  const double range_m = (Eigen::Vector3d(13.8, 2.0, 0.0) - kBeacons[0]).norm() + 0.004;
  for (auto _ : state) {
    scan::FrameFilter f = base;
    const UpdateResult r = f.update_range(Eigen::Vector2d::Zero(), 0.0, kBeacons[0], range_m, 2.5e-5);
    if (!r.applied()) state.SkipWithError("range refused");
    benchmark::DoNotOptimize(f);
  }
  state.SetLabel(scan::to_string(kKinds[state.range(0)]));
}
BENCHMARK(BM_ScanFrame_Range)->DenseRange(0, 2);

void BM_ScanFrame_Differences(benchmark::State& state) {
  const scan::FrameFilter base = frame_of(kKinds[state.range(0)]);
  std::vector<scan::EpochRange> epoch;
  for (int i = 0; i < 4; ++i) {
    const Pose2 odometry(0.008 * (i - 3), 0.0, 0.0);  // 20 ms slots at 0.4 m/s
    const Eigen::Vector3d at(13.8 + odometry.x(), 2.0, 0.0);
    epoch.push_back({kBeacons[i], (at - kBeacons[i]).norm() + 0.003 * (i - 1.5), odometry});
  }
  for (auto _ : state) {
    scan::FrameFilter f = base;
    const UpdateResult r = f.update_differences(Eigen::Vector2d::Zero(), 0.0, epoch, Pose2::Zero(), 2.5e-5);
    if (!r.applied()) state.SkipWithError("epoch refused");
    benchmark::DoNotOptimize(f);
  }
  state.SetLabel(scan::to_string(kKinds[state.range(0)]));
}
BENCHMARK(BM_ScanFrame_Differences)->DenseRange(0, 2);

void BM_Scan_InverseTrajectory(benchmark::State& state) {
  const sim::Scenario s = bench::scenario_file("seed003_scan.yaml");
  const std::vector<bench::Input> inputs = bench::simulated_inputs(s, 1, s.duration_s);
  scan::InputLog<scan::RecordedInput> log;
  for (const bench::Input& in : inputs) {
    if (in.is<OdometrySample>()) log.push_back(in.as<OdometrySample>());
    if (in.is<RangeMeasurement>()) log.push_back(in.as<RangeMeasurement>());
  }
  const EstimatorConfig config = bench::config_for(s);
  const BeaconMap map(s.beacon_list());
  std::size_t groups = 0;
  for (auto _ : state) {
    const BeaconCalibration c = scan::inverse_trajectory_calibration(config, map, log);
    groups = c.groups.size();
    benchmark::DoNotOptimize(groups);
  }
  state.counters["inputs"] = static_cast<double>(log.size());
  state.counters["groups_calibrated"] = static_cast<double>(groups);
}
BENCHMARK(BM_Scan_InverseTrajectory)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace beaconloc
