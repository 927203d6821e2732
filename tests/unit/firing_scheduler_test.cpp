// The gateway's firing scheduler (selective activation, seed 004 Sec. 3): plans checked and
// refused whole with a typed reason, the newest fresh plan followed, every beacon fired again
// once it is kFiringPlanStaleSlots slots old, and a source that fires no plan refusing them all.
#include <gtest/gtest.h>

#include "firing_scheduler.hpp"

namespace beaconloc {
namespace {

constexpr StampNs kSlotNs = 50 * kNsPerMillisecond;

TEST(FiringScheduler, FollowsTheNewestPlanUntilItIsTwoSlotsOldThenFiresEveryBeacon) {
  FiringScheduler s(kSlotNs, {1, 2, 3, 4, 5});
  EXPECT_FALSE(s.plan_at(0));  // no plan yet: every beacon
  EXPECT_FALSE(s.take({4, 2}, 1000));
  EXPECT_EQ(s.plan_at(1000), (std::vector<std::uint32_t>{2, 4}));
  EXPECT_TRUE(s.following_plan());
  EXPECT_EQ(s.plan_at(1000 + kFiringPlanStaleSlots * kSlotNs), (std::vector<std::uint32_t>{2, 4}));
  EXPECT_FALSE(s.plan_at(1001 + kFiringPlanStaleSlots * kSlotNs));  // stale: every beacon
  EXPECT_FALSE(s.following_plan());
  EXPECT_EQ(s.fallbacks(), 1u);
  EXPECT_FALSE(s.plan_at(10 * kSlotNs));
  EXPECT_EQ(s.fallbacks(), 1u);  // counted once per fall back
  // A new plan (a restarted localizer) is followed again.
  EXPECT_FALSE(s.take({5}, 20 * kSlotNs));
  EXPECT_EQ(s.plan_at(20 * kSlotNs + 1), (std::vector<std::uint32_t>{5}));
  EXPECT_EQ(s.plans_taken(), 2u);
}

TEST(FiringScheduler, RefusesABadPlanWholeAndKeepsTheOneItHas) {
  FiringScheduler s(kSlotNs, {1, 2, 3});
  ASSERT_FALSE(s.take({1}, 0));
  EXPECT_EQ(s.take({}, 10), FiringPlanRefusal::kEmpty);
  EXPECT_EQ(s.take({1, 9}, 10), FiringPlanRefusal::kUnknownBeacon);
  EXPECT_EQ(s.take({2, 2}, 10), FiringPlanRefusal::kDuplicateBeacon);
  EXPECT_EQ(s.take(std::vector<std::uint32_t>(kMaxBeacons + 1, 1), 10), FiringPlanRefusal::kTooManyBeacons);
  EXPECT_EQ(s.plan_at(20), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(s.refusals().size(), 4u);
  EXPECT_EQ(s.refusals().at(FiringPlanRefusal::kUnknownBeacon), 1u);
  EXPECT_STREQ(to_string(FiringPlanRefusal::kDuplicateBeacon), "duplicate_beacon");
  // A bad plan does not refresh the good one's age.
  EXPECT_FALSE(s.plan_at(1 + kFiringPlanStaleSlots * kSlotNs));
}

TEST(FiringScheduler, ASourceThatFiresNoPlanRefusesEveryPlan) {
  FiringScheduler replay(0, {1, 2}, false);
  EXPECT_EQ(replay.take({1}, 0), FiringPlanRefusal::kUnsupported);
  EXPECT_FALSE(replay.plan_at(0));
  EXPECT_THROW(FiringScheduler(0, {1}), std::invalid_argument);
}

}  // namespace
}  // namespace beaconloc
