// A localizer shard's view of its peers, without DDS: it serves nothing while it settles, then
// its share of the robots among the live shards of its estimator; a peer gone or back moves
// robots, a shard of another estimator moves none; every shard that sees the same set agrees.
#include "shard_membership.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace beaconloc {
namespace {

constexpr StampNs kSettled = kShardSettleNs;

std::vector<std::string> robots(int n) {
  std::vector<std::string> out;
  for (int i = 0; i < n; ++i) out.push_back("robot-" + std::to_string(i));
  return out;
}

TEST(ShardMembership, ServesNothingWhileSettlingThenEveryRobotWhenAlone) {
  ShardMembership m("a", "range_ekf", 0, kShardSettleNs);
  EXPECT_FALSE(m.settled(kShardSettleNs - 1));
  EXPECT_FALSE(m.serves("robot-1", kShardSettleNs - 1));
  EXPECT_TRUE(m.settled(kSettled));
  for (const std::string& r : robots(20)) EXPECT_TRUE(m.serves(r, kSettled)) << r;
  EXPECT_EQ(m.live_shards(), 1u);
}

TEST(ShardMembership, ShardsThatSeeTheSameSetServeEachRobotExactlyOnce) {
  ShardMembership a("a", "range_ekf", 0, kShardSettleNs);
  ShardMembership b("b", "range_ekf", 0, kShardSettleNs);
  EXPECT_TRUE(a.on_announcement("b", "range_ekf"));
  EXPECT_TRUE(b.on_announcement("a", "range_ekf"));
  EXPECT_FALSE(a.on_announcement("b", "range_ekf"));  // heard again: no change
  EXPECT_FALSE(a.on_announcement("a", "range_ekf"));  // its own, come back
  int served_by_a = 0;
  for (const std::string& r : robots(200)) {
    EXPECT_NE(a.serves(r, kSettled), b.serves(r, kSettled)) << r;
    served_by_a += a.serves(r, kSettled);
  }
  EXPECT_GT(served_by_a, 60);  // about half of 200 (binomial: 100 +- 7)
  EXPECT_LT(served_by_a, 140);
}

TEST(ShardMembership, APeerGoneLeavesItsRobotsToTheOthersAndTakesThemBackWhenAlive) {
  ShardMembership a("a", "range_ekf", 0, kShardSettleNs);
  a.on_announcement("b", "range_ekf");
  std::vector<std::string> bs;
  for (const std::string& r : robots(50)) {
    if (!a.serves(r, kSettled)) bs.push_back(r);
  }
  ASSERT_FALSE(bs.empty());
  EXPECT_TRUE(a.on_shard_gone("b"));
  for (const std::string& r : bs) EXPECT_TRUE(a.serves(r, kSettled)) << r;
  EXPECT_FALSE(a.on_shard_gone("b"));        // already gone
  EXPECT_FALSE(a.on_shard_gone("unknown"));  // never announced
  EXPECT_FALSE(a.on_shard_alive("unknown"));  // its announcement is what counts
  EXPECT_TRUE(a.on_shard_alive("b"));        // a stall longer than the lease, over
  for (const std::string& r : bs) EXPECT_FALSE(a.serves(r, kSettled)) << r;
}

TEST(ShardMembership, AShardOfAnotherEstimatorTakesNoShare) {
  ShardMembership a("a", "range_ekf", 0, kShardSettleNs);
  EXPECT_FALSE(a.on_announcement("d", "duhl"));
  EXPECT_EQ(a.live_shards(), 1u);
  EXPECT_EQ(a.other_estimator_shards(), 1u);
  for (const std::string& r : robots(20)) EXPECT_TRUE(a.serves(r, kSettled)) << r;
  EXPECT_FALSE(a.on_announcement("d", "duhl"));
  EXPECT_EQ(a.other_estimator_shards(), 1u);  // counted once
}

TEST(ShardMembership, AJoiningShardTakesRobotsOnlyFromTheShardsThatHadThem) {
  ShardMembership a("a", "range_ekf", 0, kShardSettleNs);
  a.on_announcement("b", "range_ekf");
  ShardMembership a3("a", "range_ekf", 0, kShardSettleNs);
  a3.on_announcement("b", "range_ekf");
  a3.on_announcement("c", "range_ekf");
  for (const std::string& r : robots(100)) {
    // With c added, a keeps its robots but for those c takes, and takes none from b.
    if (a3.serves(r, kSettled)) {
      EXPECT_TRUE(a.serves(r, kSettled)) << r;
    }
    if (a.serves(r, kSettled) && !a3.serves(r, kSettled)) {
      EXPECT_EQ(a3.owner(r), "c") << r;
    }
  }
}

}  // namespace
}  // namespace beaconloc
