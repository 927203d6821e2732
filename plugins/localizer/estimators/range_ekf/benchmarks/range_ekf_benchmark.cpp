// Cost of range_ekf (EKF on [x, y, yaw], one update per range) on the simulator's inputs of the
// built-in scenario (seed 000's setup: six Txs, three receivers, 100 Hz odometry), from the
// estimator as it was at a moment of the run after 10 s, on a fresh copy each iteration:
//  - BM_RangeEkf_Predict: a 100 Hz odometry step (seed 000 eq. 14, 16);
//  - BM_RangeEkf_Correct: one range fused (the range model's Jacobian, a scalar EKF update with
//    NIS gate, Joseph form).
#include <benchmark/benchmark.h>

#include "estimator_bench.hpp"

namespace beaconloc {
namespace {

using bench::Input;

struct RangeEkfScene {
  bench::Snapshot predict;  // the next input is odometry alone
  bench::Snapshot correct;  // the next input is a range
};

const RangeEkfScene& range_ekf_scene() {
  static const RangeEkfScene scene = [] {
    const sim::Scenario scenario = sim::default_scenario();
    const auto inputs = bench::simulated_inputs(scenario, 1, 30.0);
    const EstimatorConfig config = bench::config_for(scenario);
    const BeaconMap map(scenario.beacons);
    RangeEkfScene s;
    s.predict =
        bench::find_snapshot("range_ekf", config, map, inputs, 10.0,
                             [](const Estimator& e, const std::vector<Input>& in, std::size_t k) {
                               std::optional<std::vector<Input>> step = bench::next_step(in, k);
                               if (!in[k].is<OdometrySample>() || !e.estimate() || step->size() != 1)
                                 step.reset();
                               return step;
                             });
    s.correct = bench::find_snapshot("range_ekf", config, map, inputs, 10.0,
                                     [](const Estimator& e, const std::vector<Input>& in, std::size_t k) {
                                       std::optional<std::vector<Input>> step;
                                       // The first range of a firing, right after an odometry step.
                                       if (in[k].is<OdometrySample>() && e.estimate() &&
                                           k + 1 < in.size() && in[k + 1].is<RangeMeasurement>())
                                         step = std::vector<Input>{in[k + 1]};
                                       return step;
                                     });
    bench::require_accepted(s.predict, "BM_RangeEkf_Predict");
    bench::require_accepted(s.correct, "BM_RangeEkf_Correct");  // applied: a gated range is refused
    return s;
  }();
  return scene;
}

void BM_RangeEkf_Predict(benchmark::State& state) { bench::time_step(state, range_ekf_scene().predict); }
BENCHMARK(BM_RangeEkf_Predict);

void BM_RangeEkf_Correct(benchmark::State& state) { bench::time_step(state, range_ekf_scene().correct); }
BENCHMARK(BM_RangeEkf_Correct);

}  // namespace
}  // namespace beaconloc
