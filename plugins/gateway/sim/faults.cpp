#include "faults.hpp"

#include <cmath>
#include <stdexcept>

#include "beaconloc/core/decimal.hpp"
#include "beaconloc/core/limits.hpp"

namespace beaconloc::sim {

namespace {

[[noreturn]] void refuse(const std::string& spec, const std::string& why) {
  throw std::invalid_argument("fault '" + spec + "': " + why +
                              " (forms: beacon_dies=ID@T, tof_outage=FROM:TO, echoes=P)");
}

// The whole of text as a decimal number (core/decimal.hpp), or a refusal.
template <class T>
T number(const std::string& spec, const std::string& text, const char* what) {
  T v{};
  const NumberError e = parse_decimal(text, v);
  if (e != NumberError::kNone) refuse(spec, number_problem(what, text, e));
  return v;
}

// A time of the run (s): within [0, kMaxDurationS].
double time_s(const std::string& spec, const std::string& text, const char* what) {
  const double t = number<double>(spec, text, what);
  if (t < 0.0 || t > kMaxDurationS) refuse(spec, range_problem(what, t, 0.0, kMaxDurationS));
  return t;
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
    const auto beacon_id = number<std::uint32_t>(spec, value.substr(0, at), "the beacon id");
    const double t_s = time_s(spec, value.substr(at + 1), "the time");
    bool known = false;
    for (const auto& b : scenario.beacons) known = known || b.id == beacon_id;
    if (!known) refuse(spec, "the scenario has no beacon " + std::to_string(beacon_id));
    scenario.faults.beacon_dies_at_ns[beacon_id] = s_to_ns(t_s);
  } else if (kind == "tof_outage") {
    const auto colon = value.find(':');
    if (colon == std::string::npos) refuse(spec, "no ':'");
    const double from_s = time_s(spec, value.substr(0, colon), "FROM");
    const double to_s = time_s(spec, value.substr(colon + 1), "TO");
    if (!(to_s > from_s)) refuse(spec, "the outage must be 0 <= FROM < TO");
    scenario.faults.tof_outages_ns.emplace_back(s_to_ns(from_s), s_to_ns(to_s));
  } else if (kind == "echoes") {
    const double p = number<double>(spec, value, "the probability");
    if (p < 0.0 || p > 1.0) refuse(spec, "the probability is outside [0, 1]");
    scenario.echo.probability = p;
  } else {
    refuse(spec, "unknown fault '" + kind + "'");
  }
}

}  // namespace beaconloc::sim
