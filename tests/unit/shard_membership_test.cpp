// A localizer shard's view of its peers, without DDS: it serves nothing until it has settled,
// then its share of the robots among the live shards of its estimator; a peer lost or back
// moves robots, a peer gone for good is forgotten, a shard of another estimator moves none and
// one that changes its estimator is refused; every shard that sees the same set agrees.
#include "shard_membership.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace beaconloc {
namespace {

using Announcement = ShardMembership::Announcement;
constexpr StampNs kSettled = kShardSettleNs;

std::vector<std::string> robots(int n) {
  std::vector<std::string> out;
  for (int i = 0; i < n; ++i) out.push_back("robot-" + std::to_string(i));
  return out;
}

ShardMembership settled_shard(const std::string& id) {
  ShardMembership m(id, "range_ekf", kShardSettleNs);
  m.start_settling(0);
  return m;
}

TEST(ShardMembership, ServesNothingUntilSettledThenEveryRobotWhenAlone) {
  ShardMembership m("a", "range_ekf", kShardSettleNs);
  EXPECT_FALSE(m.settled(10 * kSettled));  // its settle time not started: it cannot hear yet
  EXPECT_FALSE(m.serves("robot-1", 10 * kSettled));
  m.start_settling(kSettled);
  EXPECT_FALSE(m.serves("robot-1", 2 * kSettled - 1));
  EXPECT_TRUE(m.settled(2 * kSettled));
  for (const std::string& r : robots(20)) EXPECT_TRUE(m.serves(r, 2 * kSettled)) << r;
  EXPECT_EQ(m.live_shards(), 1u);
  m.start_settling(5 * kSettled);  // again, after a stall
  EXPECT_FALSE(m.serves("robot-1", 6 * kSettled - 1));
  EXPECT_TRUE(m.serves("robot-1", 6 * kSettled));
}

TEST(ShardMembership, ShardsThatSeeTheSameSetServeEachRobotExactlyOnce) {
  ShardMembership a = settled_shard("a");
  ShardMembership b = settled_shard("b");
  EXPECT_EQ(a.on_announcement("b", "range_ekf"), Announcement::kLiveSetChanged);
  EXPECT_EQ(b.on_announcement("a", "range_ekf"), Announcement::kLiveSetChanged);
  EXPECT_EQ(a.on_announcement("b", "range_ekf"), Announcement::kNoChange);  // heard again
  EXPECT_EQ(a.on_announcement("a", "range_ekf"), Announcement::kNoChange);  // its own, come back
  int served_by_a = 0;
  for (const std::string& r : robots(200)) {
    EXPECT_NE(a.serves(r, kSettled), b.serves(r, kSettled)) << r;
    served_by_a += a.serves(r, kSettled);
  }
  EXPECT_GT(served_by_a, 60);  // about half of 200 (binomial: 100 +- 7)
  EXPECT_LT(served_by_a, 140);
}

TEST(ShardMembership, APeerLostLeavesItsRobotsToTheOthersAndTakesThemBackWhenAlive) {
  ShardMembership a = settled_shard("a");
  a.on_announcement("b", "range_ekf");
  std::vector<std::string> bs;
  for (const std::string& r : robots(50)) {
    if (!a.serves(r, kSettled)) bs.push_back(r);
  }
  ASSERT_FALSE(bs.empty());
  EXPECT_TRUE(a.on_shard_lost("b"));
  for (const std::string& r : bs) EXPECT_TRUE(a.serves(r, kSettled)) << r;
  EXPECT_FALSE(a.on_shard_lost("b"));         // already lost
  EXPECT_FALSE(a.on_shard_lost("unknown"));   // never announced
  EXPECT_FALSE(a.on_shard_alive("unknown"));  // its announcement is what counts
  EXPECT_TRUE(a.on_shard_alive("b"));         // a stall longer than the lease, over
  for (const std::string& r : bs) EXPECT_FALSE(a.serves(r, kSettled)) << r;
  EXPECT_EQ(a.known_shards(), 1u);
}

TEST(ShardMembership, AShardGoneForGoodIsForgotten) {
  ShardMembership a = settled_shard("a");
  for (int i = 0; i < 100; ++i) {  // a shard restarted 100 times: a new id each time
    const std::string id = "b" + std::to_string(i);
    a.on_announcement(id, "range_ekf");
    a.on_shard_lost(id);
    EXPECT_FALSE(a.on_shard_gone(id));  // lost already: the live set does not change again
  }
  EXPECT_EQ(a.known_shards(), 0u);
  a.on_announcement("c", "range_ekf");
  EXPECT_TRUE(a.on_shard_gone("c"));  // unmatched while live: its robots come back
  EXPECT_EQ(a.live_shards(), 1u);
}

TEST(ShardMembership, AShardOfAnotherEstimatorTakesNoShareAndNoShardChangesItsEstimator) {
  ShardMembership a = settled_shard("a");
  EXPECT_EQ(a.on_announcement("d", "duhl"), Announcement::kNoChange);
  EXPECT_EQ(a.live_shards(), 1u);
  EXPECT_EQ(a.other_estimator_shards(), 1u);
  for (const std::string& r : robots(20)) EXPECT_TRUE(a.serves(r, kSettled)) << r;
  EXPECT_EQ(a.on_announcement("d", "range_ekf"), Announcement::kEstimatorChanged);  // refused
  EXPECT_EQ(a.live_shards(), 1u);
  a.on_announcement("b", "range_ekf");
  EXPECT_EQ(a.on_announcement("b", "duhl"), Announcement::kEstimatorChanged);
  EXPECT_EQ(a.live_shards(), 2u);  // b keeps its share
}

TEST(ShardMembership, AJoiningShardTakesRobotsOnlyFromTheShardsThatHadThem) {
  ShardMembership a = settled_shard("a");
  a.on_announcement("b", "range_ekf");
  ShardMembership a3 = settled_shard("a");
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

TEST(ShardMembership, TheAnswerForARobotFollowsTheLiveSetWhateverWasAskedBefore) {
  ShardMembership a = settled_shard("a");
  for (const std::string& r : robots(30)) EXPECT_TRUE(a.serves(r, kSettled));  // every one cached
  a.on_announcement("b", "range_ekf");
  int served = 0;
  for (const std::string& r : robots(30)) served += a.serves(r, kSettled);
  EXPECT_LT(served, 30);
  a.on_shard_lost("b");
  for (const std::string& r : robots(30)) EXPECT_TRUE(a.serves(r, kSettled)) << r;
}

}  // namespace
}  // namespace beaconloc
