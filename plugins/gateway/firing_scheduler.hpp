#pragma once
// The gateway's side of selective activation (seed 004 Sec. 3), DDS-free: the plans a localizer
// sends for the gateway's robot are checked and kept, and the gateway fires by the newest one
// while it is fresh; once it is kFiringPlanStaleSlots slots old (core/firing_plan.hpp) the
// gateway fires every beacon again, so that a robot whose localizer died, stalled or lost its pose
// is never left blind. Time is the gateway's data time.
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
  kUnsupported,     // the gateway's source fires no plan (a replayed recording)
};
// Stable snake_case names, counted in the gateway's Diagnostics as firing_plan.<name>.
const char* to_string(FiringPlanRefusal refusal);

class FiringScheduler {
 public:
  // slot_period_ns > 0: the source's firing slot; beacon_ids: the beacons it can fire.
  FiringScheduler(StampNs slot_period_ns, std::set<std::uint32_t> beacon_ids, bool supported = true);
  // A plan received at now_ns: kept (the newest), or refused whole with the reason.
  std::optional<FiringPlanRefusal> take(std::vector<std::uint32_t> beacon_ids, StampNs now_ns);
  // The plan to fire by at now_ns: the newest, while it is at most kFiringPlanStaleSlots slots
  // old; nullopt (fire every beacon) before the first plan and once it is stale.
  std::optional<std::vector<std::uint32_t>> plan_at(StampNs now_ns);

  std::uint64_t plans_taken() const { return plans_taken_; }
  // Times a plan went stale and the gateway went back to firing every beacon.
  std::uint64_t fallbacks() const { return fallbacks_; }
  const std::map<FiringPlanRefusal, std::uint64_t>& refusals() const { return refusals_; }
  bool following_plan() const { return following_; }

 private:
  StampNs slot_period_ns_;
  std::set<std::uint32_t> beacon_ids_;
  bool supported_;
  std::optional<std::vector<std::uint32_t>> plan_;
  StampNs received_ns_ = 0;
  bool following_ = false;
  std::uint64_t plans_taken_ = 0;
  std::uint64_t fallbacks_ = 0;
  std::map<FiringPlanRefusal, std::uint64_t> refusals_;
};

}  // namespace beaconloc
