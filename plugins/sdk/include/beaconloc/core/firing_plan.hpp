#pragma once
// Selective activation (seed 004 Sec. 3, Fig. 3, and Sec. 4: "we measure an angle between mobile
// robot and ultrasonic sensor, and if there is an ultrasonic generator which is out of range, we
// don't active it"): which beacons to fire next, from the predicted pose and each beacon's reach.
// A slot spent on a beacon no receiver can hear is a slot without a range; firing only those
// that can reach the robot gives more ranges per second. The pose's uncertainty widens the test
// (kFiringPlanSigmas), so that a robot whose pose is off still hears the beacons it needs, and a
// plan that would fire nothing fires every beacon: a robot is never left blind.
#include <cstdint>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/pose2.hpp"
#include "beaconloc/core/receiver_array.hpp"
#include "beaconloc/core/time.hpp"

namespace beaconloc {

// How many standard deviations of the pose a beacon's reach is widened by.
inline constexpr double kFiringPlanSigmas = 3.0;
// A localizer sends a robot's plan every 20 ms of data time (50 Hz: several plans per firing slot
// of 50-200 ms).
inline constexpr StampNs kFiringPlanPeriodNs = 20 * kNsPerMillisecond;
// A gateway fires every beacon again once the pose its newest plan came from is this many firing
// slots old by the plan's stamp (the localizer gone, stalled, without a trusted pose, or its plans
// delayed): a plan that stops coming leaves a robot on it for two slots at most.
inline constexpr int kFiringPlanStaleSlots = 2;
// A fresh plan whose beacons no receiver heard for this many of its slots in a row is wrong (made
// from a pose that is off): the gateway fires every beacon for one round before it follows plans
// again, so that a stream of wrong plans cannot keep a robot blind either.
inline constexpr int kFiringPlanUnheardSlots = 3;

// The beacons to fire next, made from the pose stamped stamp_ns (the gateway judges its age by it).
struct FiringPlan {
  StampNs stamp_ns = 0;
  std::vector<std::uint32_t> beacon_ids;  // ascending
};

// Every beacon of the map (in the map frame or only in its group's), in id order: the schedule
// without a plan.
std::vector<std::uint32_t> fire_all(const BeaconMap& map);

// The beacons, in id order, that may reach a receiver of a robot at pose_map_base (covariance:
// its uncertainty) within `sigmas`: a receiver's position is widened by sigmas times the
// position's largest standard deviation plus its lever arm times the heading's. Beacons whose
// reach is not known, and locally referenced ones (no map position), are always in the plan;
// fire_all(map) when no beacon may reach the robot, or the pose or covariance is not finite.
std::vector<std::uint32_t> plan_firing(const BeaconMap& map, const ReceiverArray& receivers,
                                       const Pose2& pose_map_base, const Cov3& covariance,
                                       double sigmas = kFiringPlanSigmas);

}  // namespace beaconloc
