#include "faults.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace beaconloc::sim {

namespace {

[[noreturn]] void refuse(const std::string& spec, const std::string& why) {
  throw std::invalid_argument("fault '" + spec + "': " + why +
                              " (forms: beacon_dies=ID@T, tof_outage=FROM:TO, echoes=P)");
}

// The whole of text as a finite number, or a refusal.
double number(const std::string& spec, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v)) {
    refuse(spec, "'" + text + "' is not a number");
  }
  return v;
}

}  // namespace

void apply_fault(Scenario& scenario, const std::string& spec) {
  const auto equals = spec.find('=');
  if (equals == std::string::npos) refuse(spec, "no '='");
  const std::string kind = spec.substr(0, equals);
  const std::string value = spec.substr(equals + 1);
  if (kind == "beacon_dies") {
    const auto at = value.find('@');
    if (at == std::string::npos) refuse(spec, "no '@'");
    const double id = number(spec, value.substr(0, at));
    const double t_s = number(spec, value.substr(at + 1));
    if (id < 0 || id != std::floor(id) || id > 4294967294.0) refuse(spec, "the beacon id is not an id");
    if (t_s < 0) refuse(spec, "the time is negative");
    const auto beacon_id = static_cast<std::uint32_t>(id);
    bool known = false;
    for (const auto& b : scenario.beacons) known = known || b.id == beacon_id;
    if (!known) refuse(spec, "the scenario has no beacon " + std::to_string(beacon_id));
    scenario.faults.beacon_dies_at_ns[beacon_id] = s_to_ns(t_s);
  } else if (kind == "tof_outage") {
    const auto colon = value.find(':');
    if (colon == std::string::npos) refuse(spec, "no ':'");
    const double from_s = number(spec, value.substr(0, colon));
    const double to_s = number(spec, value.substr(colon + 1));
    if (from_s < 0 || !(to_s > from_s)) refuse(spec, "the outage must be 0 <= FROM < TO");
    scenario.faults.tof_outages_ns.emplace_back(s_to_ns(from_s), s_to_ns(to_s));
  } else if (kind == "echoes") {
    const double p = number(spec, value);
    if (p < 0.0 || p > 1.0) refuse(spec, "the probability is outside [0, 1]");
    scenario.echo.probability = p;
  } else {
    refuse(spec, "unknown fault '" + kind + "'");
  }
}

}  // namespace beaconloc::sim
