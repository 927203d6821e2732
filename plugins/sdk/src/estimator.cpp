#include "beaconloc/core/estimator.hpp"

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
