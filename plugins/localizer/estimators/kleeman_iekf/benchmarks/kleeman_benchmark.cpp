// Cost of the seed 002 estimator (kleeman_iekf) on the seed 002 setup's simulated inputs, from the
// estimator as it was 30 s into the run (tracking, the robot driving at 0.25 m/s):
//  - BM_Kleeman_Pulse: one pulse arrival, its slot's steps included: the speed measurement of
//    eq. 25, the transition of eq. 15-16 with the heading input of eq. 24, and the iterated update
//    on eq. 21's arrival time in Joseph form (eq. 11), gated (what a pulse costs the localizer);
//  - BM_Kleeman_StartupFit: the start-up fit (startup_fit.hpp) on the first two cycles of a
//    robot that stands, and on four cycles of one that drives (heading fitted too).
// The paper updates every 150 ms on a Transputer; it gives no cost.
#include <benchmark/benchmark.h>

#include "estimator_bench.hpp"
#include "kleeman_iekf/kleeman_iekf.hpp"
#include "kleeman_iekf/startup_fit.hpp"

namespace beaconloc {
namespace {

using bench::Input;

struct KleemanScene {
  sim::Scenario scenario;
  bench::Snapshot pulse;  // the estimator just before a pulse, and that pulse
};

const KleemanScene& scene() {
  static const KleemanScene s = [] {
    KleemanScene k;
    k.scenario = bench::scenario_file("seed002_kleeman.yaml");
    const auto inputs = bench::simulated_inputs(k.scenario, 1, 40.0, BeaconInput::kPulseArrivals);
    const EstimatorConfig config = bench::config_for(k.scenario);
    k.pulse = bench::find_snapshot("kleeman_iekf", config, BeaconMap(k.scenario.beacons), inputs, 30.0,
                                   [](const Estimator& e, const std::vector<Input>& in,
                                      std::size_t j) -> std::optional<std::vector<Input>> {
                                     if (j + 1 >= in.size() || !in[j + 1].is<PulseArrivalSample>() || !e.estimate())
                                       return std::nullopt;
                                     return std::vector<Input>{in[j + 1]};
                                   });
    bench::require_accepted(k.pulse, "BM_Kleeman_Pulse");
    return k;
  }();
  return s;
}

void BM_Kleeman_Pulse(benchmark::State& state) { bench::time_step(state, scene().pulse); }
BENCHMARK(BM_Kleeman_Pulse);

void BM_Kleeman_StartupFit(benchmark::State& state) {
  const sim::Scenario& s = scene().scenario;
  const bool moving = state.range(0) == 1;
  const double from_s = moving ? 20.0 : 0.0, to_s = from_s + (moving ? 3.6 : 1.8);
  const std::vector<SourceEvent> events = simulate(s, 1, to_s + 0.1);
  std::vector<kleeman::SlotPulse> pulses;
  kleeman::OdometryTrack track;
  const BeaconMap map(s.beacons);
  StampNs previous = 0;
  for (const SourceEvent& e : events) {
    const double t = ns_to_s(e.stamp_ns);
    if (e.kind == SourceEvent::Kind::kOdometry) {
      track.add(e.odometry, t, ns_to_s(e.stamp_ns - previous));
      previous = e.stamp_ns;
    }
    if (e.kind != SourceEvent::Kind::kPulse || t < from_s || t > to_s) continue;
    const auto slot = static_cast<std::int64_t>(std::floor((t - ns_to_s(s.first_slot_ns)) / ns_to_s(s.slot_period_ns)));
    pulses.push_back({slot, t, e.true_beacon_id, map.find(e.true_beacon_id)->position_map_m});
  }
  kleeman::StartupFitSettings settings;
  settings.receiver_z_m = s.receivers.receiver_height_m;
  for (auto _ : state) {
    const kleeman::StartupFit fit = kleeman::fit_startup(pulses, &track, settings);
    if (!fit.ok) {
      state.SkipWithError(("startup fit failed: " + fit.why_not).c_str());
      return;
    }
    benchmark::DoNotOptimize(fit);
  }
  state.counters["pulses"] = static_cast<double>(pulses.size());
}
BENCHMARK(BM_Kleeman_StartupFit)->Arg(0)->Arg(1);

}  // namespace
}  // namespace beaconloc
