#include "beaconloc/core/estimator.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>

#include "beaconloc/core/decimal.hpp"
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

std::map<std::string, double> parse_estimator_parameters(const std::vector<std::string>& items,
                                                         const std::string& option_name) {
  std::map<std::string, double> out;
  for (const auto& item : items) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw std::invalid_argument(option_name + " '" + item + "' is not NAME=VALUE");
    }
    const std::string value = item.substr(eq + 1);
    double v = 0.0;
    const NumberError e = parse_decimal(value, v);
    if (e != NumberError::kNone) {
      throw std::invalid_argument(option_name + " '" + item + "': " + number_problem("the value", value, e));
    }
    out[item.substr(0, eq)] = v;
  }
  return out;
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

InputResult check_initial_pose(const Pose2& pose, const Cov3& c) {
  if (!pose.allFinite() || !c.allFinite() || !c.isApprox(c.transpose(), 1e-9) ||
      Eigen::LLT<Cov3>(c).info() != Eigen::Success) {
    return InputResult::rejected("invalid_initial_pose");
  }
  return InputResult::ok();
}

}  // namespace beaconloc
