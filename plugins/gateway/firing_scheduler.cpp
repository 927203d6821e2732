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
    case FiringPlanRefusal::kInvalidStamp:
      return "invalid_stamp";
    case FiringPlanRefusal::kFromTheFuture:
      return "from_the_future";
    case FiringPlanRefusal::kStale:
      return "stale";
    case FiringPlanRefusal::kOlderThanHeld:
      return "older_than_held";
  }
  return "unknown";
}

FiringScheduler::FiringScheduler(StampNs slot_period_ns, std::set<std::uint32_t> beacon_ids)
    : slot_period_ns_(slot_period_ns), beacon_ids_(std::move(beacon_ids)) {
  if (slot_period_ns_ <= 0) throw std::invalid_argument("FiringScheduler: the slot period must be > 0");
}

std::optional<FiringPlanRefusal> FiringScheduler::take(std::vector<std::uint32_t> ids, StampNs plan_stamp_ns,
                                                       StampNs now_ns) {
  const StampNs stale_after_ns = kFiringPlanStaleSlots * slot_period_ns_;
  std::optional<FiringPlanRefusal> refusal;
  // Stamps >= 0 on both sides: their differences cannot overflow.
  if (plan_stamp_ns < 0 || now_ns < 0) {
    refusal = FiringPlanRefusal::kInvalidStamp;
  } else if (plan_stamp_ns - now_ns > slot_period_ns_) {
    refusal = FiringPlanRefusal::kFromTheFuture;
  } else if (now_ns - plan_stamp_ns > stale_after_ns) {
    refusal = FiringPlanRefusal::kStale;
  } else if (plan_ && plan_stamp_ns < plan_stamp_ns_) {
    refusal = FiringPlanRefusal::kOlderThanHeld;
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
  plan_stamp_ns_ = plan_stamp_ns;
  ++plans_taken_;
  return std::nullopt;
}

std::optional<std::vector<std::uint32_t>> FiringScheduler::plan_at(StampNs now_ns) {
  const bool fresh = plan_ && now_ns >= 0 && now_ns - plan_stamp_ns_ <= kFiringPlanStaleSlots * slot_period_ns_;
  if (following_ && !fresh) ++stale_fallbacks_;
  following_ = fresh && every_beacon_slots_left_ == 0;
  if (!following_) return std::nullopt;
  return plan_;
}

void FiringScheduler::on_firing(bool planned, bool heard) {
  if (!planned) {
    if (every_beacon_slots_left_ > 0) --every_beacon_slots_left_;
    unheard_in_row_ = 0;
    return;
  }
  unheard_in_row_ = heard ? 0 : unheard_in_row_ + 1;
  if (unheard_in_row_ >= kFiringPlanUnheardSlots) {
    every_beacon_slots_left_ = beacon_ids_.size();  // one round of every beacon
    unheard_in_row_ = 0;
    ++unheard_fallbacks_;
  }
}

}  // namespace beaconloc
