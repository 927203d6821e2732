#include "beaconloc/core/estimator.hpp"

#include <cmath>

#include "beaconloc/core/estimator_registry.hpp"

namespace beaconloc {

const char* to_string(PoseStatus s) {
  switch (s) {
    case PoseStatus::kInitializing:
      return "initializing";
    case PoseStatus::kOk:
      return "ok";
    case PoseStatus::kDegraded:
      return "degraded";
    case PoseStatus::kLost:
      return "lost";
  }
  return "unknown";
}

InputResult check_range(const RangeMeasurement& r, const BeaconMap& map, std::size_t receiver_count) {
  if (!std::isfinite(r.range_m) || !std::isfinite(r.variance_m2))
    return InputResult::rejected("non_finite_range");
  if (!(r.range_m > 0.0) || !(r.variance_m2 > 0.0)) return InputResult::rejected("invalid_range");
  if (r.beacon_id == kBeaconUnidentified) return InputResult::rejected("unassociated_range");
  if (map.empty()) return InputResult::rejected("no_beacon_map");
  if (!map.find(r.beacon_id)) return InputResult::rejected("unknown_beacon");
  if (r.receiver_id >= receiver_count) return InputResult::rejected("unknown_receiver");
  return InputResult::ok();
}

EstimatorRegistry& EstimatorRegistry::instance() {
  static EstimatorRegistry registry;
  return registry;
}

bool EstimatorRegistry::add(const std::string& name, const std::string& description,
                            EstimatorFactory factory) {
  return entries_.emplace(name, Entry{description, std::move(factory)}).second;
}

std::unique_ptr<Estimator> EstimatorRegistry::create(const std::string& name,
                                                     const EstimatorConfig& config) const {
  auto it = entries_.find(name);
  if (it == entries_.end()) {
    std::string known;
    for (const auto& [n, e] : entries_) known += (known.empty() ? "" : ", ") + n;
    throw UnknownEstimator("unknown estimator '" + name + "' (known: " + known + ")");
  }
  return it->second.factory(config);
}

std::vector<std::string> EstimatorRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [n, e] : entries_) out.push_back(n);
  return out;
}

std::string EstimatorRegistry::description(const std::string& name) const {
  auto it = entries_.find(name);
  return it == entries_.end() ? std::string() : it->second.description;
}

}  // namespace beaconloc
