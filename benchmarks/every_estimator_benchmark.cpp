// Every estimator the product registers, timed on its reference scenario (the paper setup it
// names at registration, EstimatorRegistry::reference_scenario), so that a new estimator folder is
// benchmarked with no edit here:
//  - BM_Estimator_Run/<name>: a fresh estimator pushed the first 20 s of the simulated run
//    (seed 1; odometry, the decoder's ranges, scans where the scenario has a laser), in arrival
//    order. Counters: the cost per input and per odometry step (us).
// Each estimator's own benchmarks (<name>/benchmarks/) time its steps one by one.
#include <benchmark/benchmark.h>

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
  const BeaconMap map(scenario.beacons);
  const std::vector<bench::Input> inputs = bench::simulated_inputs(scenario, 1, kRunS);
  const std::size_t odometry = bench::count<OdometrySample>(inputs);
  for (auto _ : state) {
    auto e = EstimatorRegistry::instance().create(name, config);
    e->set_beacon_map(map);
    bench::run_step(*e, inputs);
    benchmark::DoNotOptimize(e->estimate());
  }
  const double runs = static_cast<double>(state.iterations());
  state.counters["us_per_input"] = benchmark::Counter(runs * static_cast<double>(inputs.size()) * 1e-6,
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["us_per_odometry_step"] = benchmark::Counter(
      runs * static_cast<double>(odometry) * 1e-6, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace
}  // namespace beaconloc

int main(int argc, char** argv) {
  for (const std::string& name : beaconloc::shipped_estimators()) {
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
