// ShardAssignment (core/shard_assignment.hpp): every shard, on its own, gives each
// robot to one live shard, the same one for every shard that sees the same set.
#include "beaconloc/core/shard_assignment.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace beaconloc {
namespace {

std::vector<std::string> robots(int n) {
  std::vector<std::string> ids;
  for (int i = 0; i < n; ++i) ids.push_back("robot-" + std::to_string(i));
  return ids;
}

TEST(ShardAssignment, EveryShardSeeingTheSameSetGivesEachRobotToTheSameOneShard) {
  const std::vector<std::string> shards = {"shard-a", "shard-b", "shard-c"};
  std::vector<ShardAssignment> views;
  for (const std::string& s : shards) {
    views.emplace_back(s);
    views.back().set_live({"shard-c", "shard-a", "shard-b", "shard-a"});  // any order, repeats
  }
  std::map<std::string, int> served;
  for (const std::string& r : robots(3000)) {
    int owners = 0;
    for (const ShardAssignment& v : views) {
      EXPECT_EQ(v.owner(r), views.front().owner(r)) << r;
      owners += v.owns(r);
    }
    EXPECT_EQ(owners, 1) << r;
    ++served[views.front().owner(r)];
  }
  // Even shares: 1000 each, within 5 sigma of a binomial (sigma 26).
  for (const std::string& s : shards) EXPECT_NEAR(served[s], 1000, 130) << s;
}

TEST(ShardAssignment, ADeadShardsRobotsAloneMoveAndSpreadOverTheOthers) {
  ShardAssignment before("a"), after("a");
  before.set_live({"a", "b", "c", "d"});
  EXPECT_TRUE(after.set_live({"a", "b", "d"}));  // c died
  EXPECT_FALSE(after.set_live({"d", "b"}));      // self is live to itself: the same set
  std::map<std::string, int> took_over;
  for (const std::string& r : robots(4000)) {
    if (before.owner(r) != "c") {
      EXPECT_EQ(after.owner(r), before.owner(r)) << r;  // nobody else's robot moves
    } else {
      ++took_over[after.owner(r)];
    }
  }
  // About 1000 robots were c's; about a third each to a, b and d.
  ASSERT_EQ(took_over.size(), 3u);
  for (const auto& [shard, n] : took_over) EXPECT_NEAR(n, 333, 90) << shard;
}

TEST(ShardAssignment, ANewShardTakesAboutItsShareEachFromTheShardThatHadIt) {
  ShardAssignment before("a"), after("a");
  before.set_live({"a", "b"});
  after.set_live({"a", "b", "new"});
  int moved = 0;
  for (const std::string& r : robots(3000)) {
    if (after.owner(r) == before.owner(r)) continue;
    EXPECT_EQ(after.owner(r), "new") << r;  // a robot moves only to the new shard
    ++moved;
  }
  EXPECT_NEAR(moved, 1000, 130);
}

TEST(ShardAssignment, ALoneShardServesEveryRobotAndTheWeightIsFixed) {
  ShardAssignment alone("only");
  EXPECT_EQ(alone.live(), std::vector<std::string>{"only"});
  EXPECT_FALSE(alone.set_live({}));  // no peer: itself alone, as before
  for (const std::string& r : robots(100)) EXPECT_TRUE(alone.owns(r));
  // The weight is the assignment's own hash, the same on every host and build; a change to it
  // would split a fleet of mixed builds, so its values are pinned.
  EXPECT_EQ(ShardAssignment::weight("a", "b"), 16949517343777446270ULL);
  EXPECT_EQ(ShardAssignment::weight("shard-1", "robot-7"), 13092732757084632736ULL);
  EXPECT_EQ(ShardAssignment::weight("", ""), 2737183428366584608ULL);
  EXPECT_NE(ShardAssignment::weight("ab", "c"), ShardAssignment::weight("a", "bc"));
}

}  // namespace
}  // namespace beaconloc
