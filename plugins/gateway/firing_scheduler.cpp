#include "firing_scheduler.hpp"

#include <algorithm>
#include <stdexcept>

namespace beaconloc {

const char* to_string(FiringPlanRefusal refusal) {
  switch (refusal) {
    case FiringPlanRefusal::kEmpty:
      return "empty";
    case FiringPlanRefusal::kTooManyBeacons:
      return "too_many_beacons";
    case FiringPlanRefusal::kUnknownBeacon:
      return "unknown_beacon";
    case FiringPlanRefusal::kDuplicateBeacon:
      return "duplicate_beacon";
    case FiringPlanRefusal::kUnsupported:
      return "unsupported";
  }
  return "unknown";
}

FiringScheduler::FiringScheduler(StampNs slot_period_ns, std::set<std::uint32_t> beacon_ids, bool supported)
    : slot_period_ns_(slot_period_ns), beacon_ids_(std::move(beacon_ids)), supported_(supported) {
  if (supported_ && slot_period_ns_ <= 0) throw std::invalid_argument("FiringScheduler: the slot period must be > 0");
}

std::optional<FiringPlanRefusal> FiringScheduler::take(std::vector<std::uint32_t> ids, StampNs now_ns) {
  std::optional<FiringPlanRefusal> refusal;
  if (!supported_) {
    refusal = FiringPlanRefusal::kUnsupported;
  } else if (ids.empty()) {
    refusal = FiringPlanRefusal::kEmpty;
  } else if (ids.size() > kMaxBeacons) {
    refusal = FiringPlanRefusal::kTooManyBeacons;
  } else {
    std::sort(ids.begin(), ids.end());
    if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) {
      refusal = FiringPlanRefusal::kDuplicateBeacon;
    } else if (std::any_of(ids.begin(), ids.end(), [this](std::uint32_t id) { return !beacon_ids_.count(id); })) {
      refusal = FiringPlanRefusal::kUnknownBeacon;
    }
  }
  if (refusal) {
    ++refusals_[*refusal];
    return refusal;
  }
  plan_ = std::move(ids);
  received_ns_ = now_ns;
  ++plans_taken_;
  return std::nullopt;
}

std::optional<std::vector<std::uint32_t>> FiringScheduler::plan_at(StampNs now_ns) {
  const bool fresh = plan_ && now_ns - received_ns_ <= kFiringPlanStaleSlots * slot_period_ns_;
  if (following_ && !fresh) ++fallbacks_;
  following_ = fresh;
  if (!fresh) return std::nullopt;
  return plan_;
}

}  // namespace beaconloc
