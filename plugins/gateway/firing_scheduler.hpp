#pragma once
// The gateway's side of selective activation (seed 004 Sec. 3), DDS-free: the plans a localizer
// sends for the gateway's robot are checked and kept, and the source fires by the newest one while
// it is fresh, judged by the stamp of the pose it was made from. The gateway fires every beacon
// again once that pose is kFiringPlanStaleSlots slots old (the localizer died, stalled, lost its
// pose, or its plans are delayed), and for one round whenever kFiringPlanUnheardSlots planned
// firings in a row were heard by no receiver (a plan made from a wrong pose): no plan, and no
// stream of wrong plans, leaves a robot blind (core/firing_plan.hpp). Times are the gateway's
// stamps (the clock its samples carry).
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/firing_plan.hpp"

namespace beaconloc {

enum class FiringPlanRefusal {
  kEmpty,           // names no beacon
  kTooManyBeacons,  // more than kMaxBeacons
  kUnknownBeacon,   // a beacon the gateway's map does not hold
  kDuplicateBeacon, // a beacon named twice
  kInvalidStamp,    // a stamp < 0
  kFromTheFuture,   // made from a pose stamped more than a slot after the gateway's time
  kStale,           // made from a pose kFiringPlanStaleSlots slots old already when it came
  kOlderThanHeld,   // older than the plan held (delivered out of order)
};
// Stable snake_case names, counted in the gateway's Diagnostics as firing_plan.<name>.
const char* to_string(FiringPlanRefusal refusal);

class FiringScheduler {
 public:
  // slot_period_ns > 0: the source's firing slot; beacon_ids: the beacons it can fire.
  FiringScheduler(StampNs slot_period_ns, std::set<std::uint32_t> beacon_ids);
  // A plan made from the pose stamped plan_stamp_ns, received at now_ns: kept (the newest), or
  // refused whole with the reason.
  std::optional<FiringPlanRefusal> take(std::vector<std::uint32_t> beacon_ids, StampNs plan_stamp_ns, StampNs now_ns);
  // The plan to fire by at now_ns; nullopt (fire every beacon) before the first plan, once the
  // newest is stale, and during a round of every beacon after unheard planned firings.
  std::optional<std::vector<std::uint32_t>> plan_at(StampNs now_ns);
  // What a firing did: planned (by a plan) and heard (by some receiver).
  void on_firing(bool planned, bool heard);

  std::uint64_t plans_taken() const { return plans_taken_; }
  // Times the gateway went back to firing every beacon: a stale plan, unheard planned firings.
  std::uint64_t stale_fallbacks() const { return stale_fallbacks_; }
  std::uint64_t unheard_fallbacks() const { return unheard_fallbacks_; }
  const std::map<FiringPlanRefusal, std::uint64_t>& refusals() const { return refusals_; }
  bool following_plan() const { return following_; }

 private:
  StampNs slot_period_ns_;
  std::set<std::uint32_t> beacon_ids_;
  std::optional<std::vector<std::uint32_t>> plan_;
  StampNs plan_stamp_ns_ = 0;
  bool following_ = false;
  int unheard_in_row_ = 0;
  std::size_t every_beacon_slots_left_ = 0;  // of the round after unheard planned firings
  std::uint64_t plans_taken_ = 0;
  std::uint64_t stale_fallbacks_ = 0;
  std::uint64_t unheard_fallbacks_ = 0;
  std::map<FiringPlanRefusal, std::uint64_t> refusals_;
};

}  // namespace beaconloc
