// Fuzz target: the scenario YAML loader (plugins/gateway/sim/scenario_yaml.cpp) on arbitrary
// text. It must load a scenario or throw ScenarioError; any other exception (it escapes and
// aborts), a crash, undefined behaviour, a hang or a huge allocation is a bug. A scenario that
// loads must be one the simulator can run: checked cheaply on what the loader promises.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/scenario_yaml.hpp"

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

bool finite(const beaconloc::Pose2& p) { return p.allFinite(); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace beaconloc::sim;
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scenario s;
  try {
    s = parse_scenario(text, "fuzz.yaml");
  } catch (const ScenarioError&) {
    return 0;
  }
  check(!s.beacons.empty() && !s.firing_order.empty());
  check(!s.receivers.receivers_base_m.empty());
  check(std::isfinite(s.duration_s) && s.duration_s > 0.0);
  check(s.slot_period_ns > 0 && s.odometry_period_ns > 0);
  check(s.max_range_m > s.min_range_m);
  for (const auto& b : s.beacons) check(b.position_map_m.allFinite());
  // The path the simulator follows: defined over the whole run.
  check(finite(s.trajectory.pose_at(0.0)));
  check(finite(s.trajectory.pose_at(0.5 * s.duration_s)));
  check(finite(s.trajectory.pose_at(s.duration_s)));
  if (s.map) check(s.map->width() > 0 && s.map->height() > 0);
  if (s.laser) check(s.map && s.laser->beams > 0 && s.laser->period_ns > 0);
  return 0;
}
