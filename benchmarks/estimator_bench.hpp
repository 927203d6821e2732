#pragma once
// What the estimator benchmarks share: the inputs an estimator sees in a simulated scenario (the
// simulator's odometry and laser scans, its TOFs through the decoder), a snapshot of an estimator
// at a chosen moment of that run with the inputs of the step that follows, and a loop that times
// that one step again and again, each time on a fresh copy of the snapshot (so the filter never
// drifts away from the realistic state it was taken in).
#include <benchmark/benchmark.h>

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "offline_run.hpp"
#include "sim/scenario.hpp"
#include "sim/scenario_yaml.hpp"
#include "sim/sim_source.hpp"
#include "tof_decoder.hpp"

namespace beaconloc::bench {

// One input as the localizer pushes it to its estimator, with the simulator's truth.
struct Input {
  EstimatorInput input;
  Pose2 truth = Pose2::Zero();  // on odometry inputs
  template <class T>
  bool is() const {
    return std::holds_alternative<T>(input);
  }
  template <class T>
  const T& as() const {
    return std::get<T>(input);
  }
};

inline sim::Scenario scenario_file(const std::string& name) {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/" + name);
}

inline EstimatorConfig config_for(const sim::Scenario& s) {
  EstimatorConfig c;
  c.receivers = s.receivers;
  if (s.map) c.occupancy_grid = std::make_shared<const OccupancyGrid>(*s.map);
  c.initial_pose = s.trajectory.pose_at(0.0);  // placed by hand, as in seed 001
  return c;
}

// The simulated run (seed `seed`, duration_s) as the estimator's inputs, in arrival order: its
// beacon measurements as the estimator hears them (beacon_input: decoded ranges, raw TOFs or pulses).
inline std::vector<Input> simulated_inputs(const sim::Scenario& s, std::uint64_t seed, double duration_s,
                                           BeaconInput beacon_input = BeaconInput::kRanges) {
  sim::SimSource source(s, seed);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(duration_s), events);
  TofDecoder decoder = scenario_decoder(s);
  std::vector<Input> out;
  for (const SourceEvent& e : events) {
    // As the localizer is given them.
    if (std::optional<EstimatorInput> in = estimator_input("robot1", e, decoder, beacon_input)) {
      out.push_back({std::move(*in), e.truth_map_base});
    }
  }
  return out;
}

// An estimator as it was at a moment of the run, and the inputs of the step timed from there.
struct Snapshot {
  std::unique_ptr<Estimator> estimator;
  std::vector<Input> step;
  Pose2 truth = Pose2::Zero();  // at the newest odometry stamp the estimator has seen
};

// The inputs after inputs[k], up to and including the next odometry sample (empty when the run
// ends first).
inline std::vector<Input> next_step(const std::vector<Input>& inputs, std::size_t k) {
  std::vector<Input> step;
  for (std::size_t j = k + 1; j < inputs.size(); ++j) {
    step.push_back(inputs[j]);
    if (inputs[j].is<OdometrySample>()) return step;
  }
  return {};
}

// Runs `name` on the inputs and stops after the first input k (past warmup_s) for which
// step_at(estimator, inputs, k) gives the step to time. Throws when there is none.
using StepAt = std::function<std::optional<std::vector<Input>>(const Estimator&, const std::vector<Input>&,
                                                               std::size_t)>;
inline Snapshot find_snapshot(const std::string& name, const EstimatorConfig& config, const BeaconMap& map,
                              const std::vector<Input>& inputs, double warmup_s, const StepAt& step_at) {
  auto e = EstimatorRegistry::instance().create(name, config);
  e->set_beacon_map(map);
  Pose2 truth = Pose2::Zero();
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    e->push(inputs[k].input);
    if (inputs[k].is<OdometrySample>()) truth = inputs[k].truth;
    if (stamp_of(inputs[k].input) < s_to_ns(warmup_s)) continue;
    if (auto step = step_at(*e, inputs, k)) return {e->clone(), std::move(*step), truth};
  }
  throw std::logic_error(name + ": no snapshot as the benchmark wants in the simulated run");
}

template <class T>
std::size_t count(const std::vector<Input>& step) {
  std::size_t n = 0;
  for (const Input& in : step) n += in.is<T>() ? 1 : 0;
  return n;
}

// Every input of the step accepted, on a copy of the snapshot (a benchmark of refused inputs
// would time the checks only).
inline void require_accepted(const Snapshot& s, const std::string& what) {
  auto e = s.estimator->clone();
  for (const Input& in : s.step) {
    const InputResult r = e->push(in.input);
    if (!r.accepted) throw std::logic_error(what + ": input refused (" + std::string(to_string(*r.rejection)) + ")");
  }
  for (const auto& r : e->take_deferred_rejections()) throw std::logic_error(what + ": deferred " + to_string(r));
}

// One timed step: its inputs pushed in order. Out of line, so that a profiler can count it alone
// (valgrind --tool=callgrind --collect-atstart=no --toggle-collect='beaconloc::bench::run_step*').
[[gnu::noinline]] inline void run_step(Estimator& e, const std::vector<Input>& step) {
  for (const Input& in : step) {
    InputResult r = e.push(in.input);
    benchmark::DoNotOptimize(r);
  }
}

// Times the step's inputs, each iteration on its own copy of the snapshot. The copies are made
// outside the timing, a batch at a time (PauseTiming costs about a microsecond: once per batch).
inline void time_step(benchmark::State& state, const Snapshot& s) {
  constexpr std::size_t kBatch = 128;
  std::vector<std::unique_ptr<Estimator>> copies(kBatch);
  std::size_t next = kBatch;
  for (auto _ : state) {
    if (next == kBatch) {
      state.PauseTiming();
      for (auto& c : copies) c = s.estimator->clone();
      next = 0;
      state.ResumeTiming();
    }
    run_step(*copies[next++], s.step);
    benchmark::ClobberMemory();
  }
  state.counters["inputs_per_step"] = static_cast<double>(s.step.size());
}

}  // namespace beaconloc::bench
