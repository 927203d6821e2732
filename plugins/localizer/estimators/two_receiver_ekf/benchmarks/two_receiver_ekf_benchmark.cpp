// Cost of two_receiver_ekf (seed 004: one 2-state EKF per receiver) on the simulator's inputs of
// the seed 004 room (nine generators, 50 ms slots, two receivers, 100 Hz odometry), from the
// estimator as it was at a moment of the run after 10 s, on a fresh copy each iteration:
//  - BM_TwoReceiverEkf_Predict: a 100 Hz odometry step (each receiver moved, eq. 3, and the pair's
//    pose for the heading, eq. 11-12);
//  - BM_TwoReceiverEkf_Correct: one range fused into its receiver's EKF (eq. 4-10).
#include <benchmark/benchmark.h>

#include "estimator_bench.hpp"

namespace beaconloc {
namespace {

using bench::Input;

struct TwoReceiverScene {
  bench::Snapshot predict;
  bench::Snapshot correct;
};

const TwoReceiverScene& two_receiver_scene() {
  static const TwoReceiverScene scene = [] {
    const sim::Scenario scenario = bench::scenario_file("seed004_two_receivers.yaml");
    const auto inputs = bench::simulated_inputs(scenario, 1, 20.0);
    const EstimatorConfig config = bench::config_for(scenario);
    const BeaconMap map(scenario.beacon_list());
    TwoReceiverScene s;
    s.predict = bench::find_snapshot("two_receiver_ekf", config, map, inputs, 10.0,
                                     [](const Estimator& e, const std::vector<Input>& in, std::size_t k) {
                                       std::optional<std::vector<Input>> step = bench::next_step(in, k);
                                       if (!in[k].is<OdometrySample>() || !e.estimate() || step->size() != 1)
                                         step.reset();
                                       return step;
                                     });
    s.correct = bench::find_snapshot("two_receiver_ekf", config, map, inputs, 10.0,
                                     [](const Estimator& e, const std::vector<Input>& in, std::size_t k) {
                                       std::optional<std::vector<Input>> step;
                                       if (in[k].is<OdometrySample>() && e.estimate() && k + 1 < in.size() &&
                                           in[k + 1].is<RangeMeasurement>())
                                         step = std::vector<Input>{in[k + 1]};
                                       return step;
                                     });
    bench::require_accepted(s.predict, "BM_TwoReceiverEkf_Predict");
    bench::require_accepted(s.correct, "BM_TwoReceiverEkf_Correct");
    return s;
  }();
  return scene;
}

void BM_TwoReceiverEkf_Predict(benchmark::State& state) { bench::time_step(state, two_receiver_scene().predict); }
BENCHMARK(BM_TwoReceiverEkf_Predict);

void BM_TwoReceiverEkf_Correct(benchmark::State& state) { bench::time_step(state, two_receiver_scene().correct); }
BENCHMARK(BM_TwoReceiverEkf_Correct);

}  // namespace
}  // namespace beaconloc
