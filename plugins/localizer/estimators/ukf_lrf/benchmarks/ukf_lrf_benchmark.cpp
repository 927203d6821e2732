// Cost of the seed 001 UKF (ukf_lrf, fusion mode) on the simulator's inputs of the classroom
// scenario (four anonymous ceiling beacons, a 19-beam laser every 22 ms, odometry every 22 ms,
// the 10 cm occupancy grid), from the estimator as it was at a moment of the run after 10 s, on
// a fresh copy each iteration:
//  - BM_UkfLrf_Predict: an odometry step with no measurement held: the augmented state of the
//    pose and the two velocity noises (L = 5, 11 sigma points) through eq. 9-13;
//  - BM_UkfLrf_LaserUpdate/19: a scan of 19 usable beams fused at the filter's time, as the
//    simulator delivers it (the scan right after the odometry of its stamp): no motion terms,
//    L = 3 + 19, 45 sigma points, every pose-moving one ray cast for the 19 beams (eq. 15-22);
//  - BM_UkfLrf_FusedUpdate/beams:19/ranges:R: one iteration of Table 1 with everything at once,
//    as the paper runs it: R anonymous beacon ranges and the 19-beam scan held, then the odometry
//    step that predicts (eq. 9-13), associates each range (Table 2) and corrects (eq. 15-22). L =
//    3 + 2 + R + 19; R = 4 is the paper's 28-element state (57 sigma points). R = 0 is the
//    simulator's scan; R = 1 adds the range the simulator delivered in that step; R = 4 takes the
//    four beacons' ranges from the true pose with the scenario's range noise.
// The paper: 8 ms per iteration (MATLAB, i7-3770 at 3.4 GHz, Sec. 4.1).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "beaconloc/core/models/range_model.hpp"
#include "estimator_bench.hpp"

namespace beaconloc {
namespace {

using bench::Input;

struct UkfScene {
  sim::Scenario scenario;
  std::vector<Input> inputs;
  EstimatorConfig config;
  BeaconMap map;
};

const UkfScene& ukf_scene() {
  static const UkfScene scene = [] {
    UkfScene s;
    s.scenario = bench::scenario_file("seed001_classroom.yaml");
    s.inputs = bench::simulated_inputs(s.scenario, 1, 30.0);
    s.config = bench::config_for(s.scenario);
    s.map = BeaconMap(s.scenario.beacons);
    return s;
  }();
  return scene;
}

std::size_t usable_beams(const LaserScanSample& scan) {
  std::size_t n = 0;
  for (float r : scan.ranges_m) n += std::isfinite(r) && r > scan.range_min_m && r < scan.range_max_m ? 1 : 0;
  return n;
}

void BM_UkfLrf_Predict(benchmark::State& state) {
  const UkfScene& u = ukf_scene();
  static const bench::Snapshot snapshot =
      bench::find_snapshot("ukf_lrf", u.config, u.map, u.inputs, 10.0,
                           [](const Estimator&, const std::vector<Input>& in, std::size_t k) {
                             std::optional<std::vector<Input>> step = bench::next_step(in, k);
                             if (!in[k].is<LaserScanSample>() || step->size() != 1) step.reset();
                             return step;
                           });
  bench::require_accepted(snapshot, "BM_UkfLrf_Predict");
  bench::time_step(state, snapshot);
}
BENCHMARK(BM_UkfLrf_Predict);

void BM_UkfLrf_LaserUpdate(benchmark::State& state) {
  const UkfScene& u = ukf_scene();
  const std::size_t beams = static_cast<std::size_t>(state.range(0));
  const bench::Snapshot snapshot = bench::find_snapshot(
      "ukf_lrf", u.config, u.map, u.inputs, 10.0,
      [&](const Estimator&, const std::vector<Input>& in,
          std::size_t k) -> std::optional<std::vector<Input>> {
        if (!in[k].is<OdometrySample>() || k + 1 >= in.size() ||
            !in[k + 1].is<LaserScanSample>() || usable_beams(in[k + 1].as<LaserScanSample>()) != beams)
          return std::nullopt;
        return std::vector<Input>{in[k + 1]};
      });
  bench::require_accepted(snapshot, "BM_UkfLrf_LaserUpdate");
  bench::time_step(state, snapshot);
  state.counters["beams"] = static_cast<double>(beams);
}
BENCHMARK(BM_UkfLrf_LaserUpdate)->Arg(19);

void BM_UkfLrf_FusedUpdate(benchmark::State& state) {
  const UkfScene& u = ukf_scene();
  const std::size_t beams = static_cast<std::size_t>(state.range(0));
  const int ranges = static_cast<int>(state.range(1));
  const bench::Snapshot snapshot =
      bench::find_snapshot("ukf_lrf", u.config, u.map, u.inputs, 10.0,
                           [&](const Estimator&, const std::vector<Input>& in,
                               std::size_t k) -> std::optional<std::vector<Input>> {
                             // Right after a scan was fused; the next odometry step's scan follows that
                             // odometry.
                             if (!in[k].is<LaserScanSample>()) return std::nullopt;
                             std::vector<Input> step = bench::next_step(in, k);
                             const std::size_t next = k + step.size() + 1;
                             if (step.empty() || next >= in.size() || !in[next].is<LaserScanSample>() ||
                                 usable_beams(in[next].as<LaserScanSample>()) != beams)
                               return std::nullopt;
                             const std::size_t sim_ranges = bench::count<RangeMeasurement>(step);
                             if (sim_ranges != (ranges == 1 ? 1u : 0u) || step.size() != sim_ranges + 1)
                               return std::nullopt;
                             const Input odometry = step.back();
                             step.pop_back();
                             if (ranges == 4) {
                               // The four beacons' ranges at the true pose of the odometry stamp, with the
                               // range noise.
                               std::mt19937_64 rng(1);
                               std::normal_distribution<double> noise(0.0, u.scenario.range_sigma_m);
                               const ReceiverArray& rx = u.scenario.receivers;
                               for (const Beacon& b : u.scenario.beacons) {
                                 const StampNs stamp_ns = stamp_of(odometry.input);
                                 RangeMeasurement r;
                                 r.stamp_ns = stamp_ns;
                                 r.receiver_id = 0;
                                 r.range_m = predict_range(odometry.truth, rx.receivers_base_m[0],
                                                                 rx.receiver_height_m, b.position_map_m)
                                                       .range_m +
                                                   noise(rng);
                                 r.variance_m2 = u.scenario.range_sigma_m * u.scenario.range_sigma_m;
                                 step.push_back({r, odometry.truth});
                               }
                             }
                             step.push_back(in[next]);  // the scan, held (stamped after the filter's time)
                             step.push_back(odometry);  // the step that fuses it all
                             return step;
                           });
  bench::require_accepted(snapshot, "BM_UkfLrf_FusedUpdate");
  bench::time_step(state, snapshot);
  state.counters["beams"] = static_cast<double>(beams);
  state.counters["ranges"] = static_cast<double>(ranges);
}
BENCHMARK(BM_UkfLrf_FusedUpdate)->ArgNames({"beams", "ranges"})->Args({19, 0})->Args({19, 1})->Args({19, 4});

}  // namespace
}  // namespace beaconloc
