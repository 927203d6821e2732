// Cost of the seed 000 DUHL estimator (duhl) and of its UHL, with 6 and with 10 Txs in the
// available set T_A, on the simulator's inputs: the built-in scenario (six Txs at z_T = 2.011 m,
// the setup of trajectories 1-2) and the same loop under ten Txs at z_T = 1.887 m (duhl_scenario),
// both with sigma_dd = 0.01 m and 100 Hz odometry with k_v = 4e-4 m. Each benchmark starts from the
// estimator as it was at a moment of the run (after 10 s) with that many Txs available, and times
// the inputs that came next, on a fresh copy each iteration:
//  - BM_Duhl_Predict/N: a 100 Hz odometry step without a correction (eq. 14, 16, and eq. 23-24
//    and the discard test of eq. 31-32 for every Tx);
//  - BM_Duhl_RangeUpdate/N: the three ranges of one firing (eq. 25-27, one scalar update per
//    receiver), the UHL not yet run;
//  - BM_Duhl_Step/N: a full DUHL step: those three ranges, then the odometry step that predicts
//    (as above) and corrects: the UHL on the N Txs' distances (Table I), R of eq. 21 through the
//    UHL's Jacobian, the EKF update of eq. 17-20. The correction alone is Step - Predict;
//  - BM_Uhl/N: the UHL alone (solve_uhl, Table I: DM heading eq. 4-9, DM position eq. 10, IMR
//    multilateration eq. 11), no EKF, on the distances from the true pose to the N Txs with
//    sigma_dd = 0.01 m noise.
// The paper's Table III: 0.55-0.97 ms per step on a 2.66 GHz laptop, 0.97 ms for trajectory 3.
#include <benchmark/benchmark.h>

#include <map>
#include <random>
#include <stdexcept>

#include "beaconloc/core/models/range_model.hpp"
#include "duhl/duhl_estimator.hpp"
#include "estimator_bench.hpp"

namespace beaconloc {
namespace {

using bench::Input;

// The scenario with n Txs: 6, the built-in one (seed 000 trajectories 1-2: a 3 x 2 grid at
// z_T = 2.011 m over a 2 m x 1.2 m loop). 10: the same loop under a 5 x 2 grid at trajectory 3's
// z_T = 1.887 m, 1.2 m apart, so that all ten stay in T_A (on trajectory 3's own 8.8 m hall the
// robot hears at most a few of its ten Txs at a time).
sim::Scenario duhl_scenario(int n) {
  sim::Scenario s = sim::default_scenario();
  if (n == 6) return s;
  if (n != 10) throw std::invalid_argument("duhl benchmarks: 6 or 10 Txs");
  s.beacons.clear();
  s.firing_order.clear();
  for (std::uint32_t i = 0; i < 10; ++i) {
    s.beacons.push_back({i + 1, {-0.9 + 1.2 * (i % 5), -0.3 + 1.8 * (i / 5), 1.887}, 0});
    s.firing_order.push_back(i + 1);
  }
  return s;
}

std::size_t available(const Estimator& e) { return dynamic_cast<const duhl::Duhl&>(e).available_txs(); }

double trace(const Estimator& e) { return e.estimate() ? e.estimate()->covariance.trace() : 0.0; }

struct DuhlScene {
  bench::Snapshot predict;  // the next input is odometry alone
  bench::Snapshot step;     // the next inputs: one firing heard by the three receivers, then odometry
  sim::Scenario scenario;
};

// One scene per Tx count, built on first use (the simulated runs take a moment).
const DuhlScene& scene(int n) {
  static std::map<int, DuhlScene> scenes;
  auto it = scenes.find(n);
  if (it != scenes.end()) return it->second;
  DuhlScene s;
  s.scenario = duhl_scenario(n);
  const auto inputs = bench::simulated_inputs(s.scenario, 1, 60.0);
  const EstimatorConfig config = bench::config_for(s.scenario);
  const BeaconMap map(s.scenario.beacons);
  const std::size_t txs = static_cast<std::size_t>(n);
  s.predict = bench::find_snapshot(
      "duhl", config, map, inputs, 10.0,
      [&](const Estimator& e, const std::vector<Input>& in, std::size_t k) {
        std::optional<std::vector<Input>> step = bench::next_step(in, k);
        if (!in[k].is<OdometrySample>() || !e.estimate() || available(e) != txs || step->size() != 1)
          step.reset();
        return step;
      });
  s.step = bench::find_snapshot(
      "duhl", config, map, inputs, 10.0,
      [&](const Estimator& e, const std::vector<Input>& in,
          std::size_t k) -> std::optional<std::vector<Input>> {
        const std::vector<Input> step = bench::next_step(in, k);
        if (!in[k].is<OdometrySample>() || !e.estimate() || available(e) != txs ||
            step.size() != 4 || bench::count<RangeMeasurement>(step) != 3 ||
            step[0].as<RangeMeasurement>().beacon_id != step[2].as<RangeMeasurement>().beacon_id)
          return std::nullopt;
        // The correction applied (not gated), on the N Txs.
        auto predicted = e.clone(), corrected = e.clone();
        predicted->push(step.back().input);
        for (const Input& input : step) corrected->push(input.input);
        if (available(*corrected) != txs || !(trace(*corrected) < trace(*predicted))) return std::nullopt;
        return step;
      });
  bench::require_accepted(s.predict, "BM_Duhl_Predict");
  bench::require_accepted(s.step, "BM_Duhl_Step");
  return scenes.emplace(n, std::move(s)).first->second;
}

void BM_Duhl_Predict(benchmark::State& state) {
  const DuhlScene& s = scene(static_cast<int>(state.range(0)));
  bench::time_step(state, s.predict);
  state.counters["txs"] = static_cast<double>(available(*s.predict.estimator));
}
BENCHMARK(BM_Duhl_Predict)->Arg(6)->Arg(10);

void BM_Duhl_RangeUpdate(benchmark::State& state) {
  const DuhlScene& s = scene(static_cast<int>(state.range(0)));
  bench::Snapshot ranges{
      s.step.estimator->clone(), {s.step.step.begin(), s.step.step.end() - 1}, s.step.truth};
  bench::time_step(state, ranges);
  state.counters["txs"] = static_cast<double>(available(*s.step.estimator));
}
BENCHMARK(BM_Duhl_RangeUpdate)->Arg(6)->Arg(10);

void BM_Duhl_Step(benchmark::State& state) {
  const DuhlScene& s = scene(static_cast<int>(state.range(0)));
  bench::time_step(state, s.step);
  state.counters["txs"] = static_cast<double>(available(*s.step.estimator));
}
BENCHMARK(BM_Duhl_Step)->Arg(6)->Arg(10);

// The UHL alone on the scenario's N Txs, from the true pose at the Step snapshot.
void BM_Uhl(benchmark::State& state) {
  const DuhlScene& s = scene(static_cast<int>(state.range(0)));
  const ReceiverArray& receivers = s.scenario.receivers;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, s.scenario.range_sigma_m);
  std::vector<duhl::TxDistances> txs;
  for (const Beacon& b : s.scenario.beacons) {
    duhl::TxDistances t;
    t.tx_map_m = b.position_map_m;
    for (int l = 0; l < 3; ++l) {
      t.distances_m(l) = predict_range(s.step.truth, receivers.receivers_base_m[l],
                                       receivers.receiver_height_m, b.position_map_m)
                             .range_m +
                         noise(rng);
    }
    txs.push_back(t);
  }
  duhl::UhlOptions options;
  options.receiver_radius_m = receivers.receivers_base_m[0].norm();
  options.receiver_height_m = receivers.receiver_height_m;
  if (!duhl::solve_uhl(txs, options).ok) throw std::logic_error("BM_Uhl: no UHL solution");
  for (auto _ : state) benchmark::DoNotOptimize(duhl::solve_uhl(txs, options));
  state.counters["txs"] = static_cast<double>(txs.size());
}
BENCHMARK(BM_Uhl)->Arg(6)->Arg(10);

}  // namespace
}  // namespace beaconloc

