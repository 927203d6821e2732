// The gateway's firing scheduler (selective activation, seed 004 Sec. 3): plans checked and
// refused whole with a typed reason, the newest fresh plan followed, every beacon fired again once
// the pose the plan came from is kFiringPlanStaleSlots slots old, and for a round after
// kFiringPlanUnheardSlots unheard planned firings.
#include <gtest/gtest.h>

#include <limits>

#include "firing_scheduler.hpp"

namespace beaconloc {
namespace {

constexpr StampNs kSlotNs = 50 * kNsPerMillisecond;
constexpr StampNs kStaleNs = kFiringPlanStaleSlots * kSlotNs;

TEST(FiringScheduler, FollowsTheNewestPlanUntilThePoseItCameFromIsTwoSlotsOldThenFiresEveryBeacon) {
  const StampNs t = 1'000'000'000'000;
  FiringScheduler s(kSlotNs, {1, 2, 3, 4, 5});
  EXPECT_FALSE(s.plan_at(t));  // no plan yet: every beacon
  EXPECT_FALSE(s.take({4, 2}, t - 5'000'000, t));  // made from a pose 5 ms old
  EXPECT_EQ(s.plan_at(t), (std::vector<std::uint32_t>{2, 4}));
  EXPECT_TRUE(s.following_plan());
  EXPECT_EQ(s.plan_at(t - 5'000'000 + kStaleNs), (std::vector<std::uint32_t>{2, 4}));
  EXPECT_FALSE(s.plan_at(t - 5'000'000 + kStaleNs + 1));  // stale: every beacon
  EXPECT_FALSE(s.following_plan());
  EXPECT_EQ(s.stale_fallbacks(), 1u);
  EXPECT_FALSE(s.plan_at(t + 10 * kSlotNs));
  EXPECT_EQ(s.stale_fallbacks(), 1u);  // counted once per fall back
  // A new plan (a restarted localizer) is followed again.
  EXPECT_FALSE(s.take({5}, t + 20 * kSlotNs, t + 20 * kSlotNs + 1));
  EXPECT_EQ(s.plan_at(t + 20 * kSlotNs + 1), (std::vector<std::uint32_t>{5}));
  EXPECT_EQ(s.plans_taken(), 2u);
}

TEST(FiringScheduler, RefusesABadPlanWholeAndKeepsTheOneItHas) {
  const StampNs t = 5 * kNsPerSecond;
  FiringScheduler s(kSlotNs, {1, 2, 3});
  ASSERT_FALSE(s.take({1}, t, t));
  EXPECT_EQ(s.take({}, t, t), FiringPlanRefusal::kEmpty);
  EXPECT_EQ(s.take({1, 9}, t, t), FiringPlanRefusal::kUnknownBeacon);
  EXPECT_EQ(s.take({2, 2}, t, t), FiringPlanRefusal::kDuplicateBeacon);
  EXPECT_EQ(s.take(std::vector<std::uint32_t>(kMaxBeacons + 1, 1), t, t), FiringPlanRefusal::kTooManyBeacons);
  // Stamps: negative, absurd either way, stale on arrival, older than the plan held.
  EXPECT_EQ(s.take({2}, -1, t), FiringPlanRefusal::kInvalidStamp);
  EXPECT_EQ(s.take({2}, std::numeric_limits<StampNs>::min(), t), FiringPlanRefusal::kInvalidStamp);
  EXPECT_EQ(s.take({2}, std::numeric_limits<StampNs>::max(), t), FiringPlanRefusal::kFromTheFuture);
  EXPECT_EQ(s.take({2}, t + kSlotNs + 1, t), FiringPlanRefusal::kFromTheFuture);
  EXPECT_EQ(s.take({2}, t - kStaleNs - 1, t), FiringPlanRefusal::kStale);
  EXPECT_EQ(s.take({2}, 0, t), FiringPlanRefusal::kStale);
  EXPECT_EQ(s.take({2}, t - 1, t), FiringPlanRefusal::kOlderThanHeld);
  EXPECT_EQ(s.plan_at(t + 10), (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(s.refusals().size(), 8u);
  EXPECT_EQ(s.refusals().at(FiringPlanRefusal::kStale), 2u);
  EXPECT_STREQ(to_string(FiringPlanRefusal::kDuplicateBeacon), "duplicate_beacon");
  EXPECT_STREQ(to_string(FiringPlanRefusal::kOlderThanHeld), "older_than_held");
  // A bad plan does not refresh the good one's age.
  EXPECT_FALSE(s.plan_at(t + kStaleNs + 1));
  EXPECT_THROW(FiringScheduler(0, {1}), std::invalid_argument);
}

// Plans that keep coming but name beacons nobody hears (made from a wrong pose): after
// kFiringPlanUnheardSlots such firings in a row, one round of every beacon, then plans again.
TEST(FiringScheduler, UnheardPlannedFiringsBringARoundOfEveryBeacon) {
  const StampNs t = kNsPerSecond;
  FiringScheduler s(kSlotNs, {1, 2, 3, 4});
  ASSERT_FALSE(s.take({1}, t, t));
  for (int i = 0; i < kFiringPlanUnheardSlots - 1; ++i) {
    ASSERT_TRUE(s.plan_at(t));
    s.on_firing(true, false);
  }
  s.on_firing(true, true);  // one heard: the count starts again
  for (int i = 0; i < kFiringPlanUnheardSlots; ++i) {
    ASSERT_TRUE(s.plan_at(t)) << i;
    s.on_firing(true, false);
  }
  EXPECT_EQ(s.unheard_fallbacks(), 1u);
  for (int round = 0; round < 4; ++round) {
    ASSERT_TRUE(s.take({1}, t, t) == std::nullopt);  // fresh plans keep coming
    EXPECT_FALSE(s.plan_at(t)) << round;              // but every beacon fires for a round
    s.on_firing(false, round % 2 == 0);
  }
  EXPECT_TRUE(s.plan_at(t));
  EXPECT_EQ(s.stale_fallbacks(), 0u);
}

}  // namespace
}  // namespace beaconloc
