// Every estimator the product registers, timed on its reference scenario (the paper setup it
// names at registration, EstimatorRegistry::reference_scenario), so that a new estimator folder is
// benchmarked with no edit here:
//  - BM_Estimator_Run/<name>: a fresh estimator pushed the first 20 s of the simulated run
//    (seed 1; odometry, the decoder's ranges, scans where the scenario has a laser), in arrival
//    order. Counters: the cost per input and per odometry step (us), and the share of the inputs
//    it refused (an error when most: that would time the checks, not the estimator).
// Each estimator's own benchmarks (<name>/benchmarks/) time its steps one by one.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "estimator_bench.hpp"
#include "shipped_estimators.hpp"

namespace beaconloc {
namespace {

constexpr double kRunS = 20.0;

void run_estimator(benchmark::State& state, const std::string& name) {
  const sim::Scenario scenario = bench::scenario_file(EstimatorRegistry::instance().reference_scenario(name));
  const EstimatorConfig config = bench::config_for(scenario);
  const BeaconMap map(scenario.beacon_list());  // as the gateway publishes it (never the truth of local groups)
  const BeaconInput beacon_input = EstimatorRegistry::instance().create(name, config)->beacon_input();
  const std::vector<bench::Input> inputs = bench::simulated_inputs(scenario, 1, kRunS, beacon_input);
  const std::size_t odometry = bench::count<OdometrySample>(inputs);
  // What it refuses of them (gated, before its first fix, ...), counted once outside the timing:
  // a run that refuses most of its inputs times the checks, not the estimator.
  std::size_t refused = 0;
  {
    auto e = EstimatorRegistry::instance().create(name, config);
    e->set_beacon_map(map);
    for (const bench::Input& in : inputs) refused += e->push(in.input).accepted ? 0 : 1;
  }
  if (2 * refused > inputs.size()) {
    state.SkipWithError((name + " refuses most of its reference scenario's inputs").c_str());
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    auto e = EstimatorRegistry::instance().create(name, config);
    e->set_beacon_map(map);
    bench::run_step(*e, inputs);
    benchmark::DoNotOptimize(e->estimate());
  }
  // Wall time over the timed loop (Google Benchmark's "Time" column), per input and per step.
  const double us_per_run = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() /
                            static_cast<double>(state.iterations());
  state.counters["us_per_input"] = us_per_run / static_cast<double>(inputs.size());
  state.counters["us_per_odometry_step"] = us_per_run / static_cast<double>(odometry);
  state.counters["refused_share"] = static_cast<double>(refused) / static_cast<double>(inputs.size());
}

}  // namespace
}  // namespace beaconloc

int main(int argc, char** argv) {
  for (const std::string& name : beaconloc::shipped_estimators()) {
    if (beaconloc::EstimatorRegistry::instance().reference_scenario(name).empty()) {
      std::fprintf(stderr, "BM_Estimator_Run: %s names no reference scenario, not timed\n", name.c_str());
      continue;
    }
    benchmark::RegisterBenchmark(("BM_Estimator_Run/" + name).c_str(),
                                 [name](benchmark::State& state) { beaconloc::run_estimator(state, name); })
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
