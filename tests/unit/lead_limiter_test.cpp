// The one-process run's lead limit (plugins/gateway/lead_limiter.hpp): a sample lost on the way
// holds the gateway back once, then is counted lost and never waited for again.
#include "lead_limiter.hpp"

#include <gtest/gtest.h>

namespace beaconloc {
namespace {

TEST(LeadLimiter, HoldsTheProducerBackWhileAConsumerLacksMoreThanItsLead) {
  LeadLimiter lead({25, 8});
  EXPECT_FALSE(lead.lagging({{125, 100}, {8, 0}}));  // exactly the leads
  EXPECT_TRUE(lead.lagging({{126, 100}, {8, 0}}));
  EXPECT_TRUE(lead.lagging({{125, 100}, {9, 0}}));
}

TEST(LeadLimiter, ASampleGivenUpOnHoldsItBackOnceNotAtEveryLaterStep) {
  LeadLimiter lead({25, 8});
  // The decoder never gets 9 of the TOFs (past their lifespan): it lacks 9 for good.
  EXPECT_TRUE(lead.lagging({{100, 100}, {30, 21}}));
  lead.give_up({{100, 100}, {30, 21}});
  EXPECT_EQ(lead.lost(1), 9u);
  EXPECT_EQ(lead.lost(0), 0u);
  EXPECT_FALSE(lead.lagging({{100, 100}, {30, 21}}));
  // Every later step: the consumers keep up with what comes, the loss holds nothing back...
  EXPECT_FALSE(lead.lagging({{110, 110}, {31, 22}}));
  EXPECT_EQ(lead.missing(1, {31, 22}), 0u);
  // ...and a consumer that lags again is held back on, beyond what was lost.
  EXPECT_TRUE(lead.lagging({{110, 110}, {40, 22}}));
  EXPECT_EQ(lead.missing(1, {40, 22}), 9u);
}

TEST(LeadLimiter, GivingUpAgainCountsTheWholeShortfallOnce) {
  LeadLimiter lead({25});
  lead.give_up({{50, 40}});
  lead.give_up({{80, 65}});  // 15 missing in all, the first 10 among them
  EXPECT_EQ(lead.lost(0), 15u);
  // A sample late, not lost, processed after all: never negative, never held back for it.
  EXPECT_EQ(lead.missing(0, {80, 80}), 0u);
  EXPECT_FALSE(lead.lagging({{80, 80}}));
}

}  // namespace
}  // namespace beaconloc
