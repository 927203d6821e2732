// Two localizers serving one robot find each other from their Diagnostics' robot lists, without
// DDS here: the conflict degrades the robot's poses, names robot and peer, is counted once, and
// clears when the peer stops serving the robot, leaves, or falls silent.
#include "serving_conflicts.hpp"

#include <gtest/gtest.h>

namespace beaconloc {
namespace {

constexpr StampNs kSilentNs = 3 * kNsPerSecond;

TEST(ServingConflicts, ARobotAPeerServesTooIsContestedNamedCountedAndItsOkPosesDegraded) {
  ServingConflicts c(kSilentNs);
  c.set_own_robots({"r1", "r2"}, 0);
  EXPECT_FALSE(c.contested("r1"));
  c.on_peer_report("peer-a", "beaconloc.localizer.duhl", {"r1", "r9"}, 100);
  EXPECT_TRUE(c.contested("r1"));
  EXPECT_FALSE(c.contested("r2"));  // the peer does not serve it
  EXPECT_FALSE(c.contested("r9"));  // this localizer does not serve it
  EXPECT_EQ(c.contested_robots(), 1u);
  EXPECT_EQ(c.conflicts_found(), 1u);
  EXPECT_EQ(c.describe(), "robot r1 also served by beaconloc.localizer.duhl");
  EXPECT_EQ(c.status_of("r1", PoseStatus::kOk), PoseStatus::kDegraded);
  EXPECT_EQ(c.status_of("r1", PoseStatus::kInitializing), PoseStatus::kInitializing);
  EXPECT_EQ(c.status_of("r1", PoseStatus::kLost), PoseStatus::kLost);
  EXPECT_EQ(c.status_of("r2", PoseStatus::kOk), PoseStatus::kOk);
  // The same peer reporting again, 1 s later: the same conflict, not a new one.
  c.on_peer_report("peer-a", "beaconloc.localizer.duhl", {"r1", "r9"}, kNsPerSecond);
  EXPECT_EQ(c.conflicts_found(), 1u);
}

TEST(ServingConflicts, ClearsWhenThePeerLeavesFallsSilentOrStopsServingTheRobot) {
  ServingConflicts c(kSilentNs);
  c.set_own_robots({"r1"}, 0);
  c.on_peer_report("peer-a", "a", {"r1"}, 0);
  ASSERT_TRUE(c.contested("r1"));
  c.on_peer_gone("peer-a", 10);
  EXPECT_FALSE(c.contested("r1"));
  EXPECT_EQ(c.status_of("r1", PoseStatus::kOk), PoseStatus::kOk);
  EXPECT_EQ(c.describe(), "");

  c.on_peer_report("peer-a", "a", {"r1"}, kNsPerSecond);
  EXPECT_EQ(c.conflicts_found(), 2u);   // it began again
  c.refresh(kNsPerSecond + kSilentNs);  // silent for exactly the limit: still there
  EXPECT_TRUE(c.contested("r1"));
  c.refresh(kNsPerSecond + kSilentNs + 1);
  EXPECT_FALSE(c.contested("r1"));

  c.on_peer_report("peer-a", "a", {"r1"}, 10 * kNsPerSecond);
  ASSERT_TRUE(c.contested("r1"));
  c.on_peer_report("peer-a", "a", {"r2"}, 11 * kNsPerSecond);
  EXPECT_FALSE(c.contested("r1"));
  c.on_peer_report("peer-a", "a", {"r1"}, 12 * kNsPerSecond);
  ASSERT_TRUE(c.contested("r1"));
  c.on_peer_report("peer-a", "a", {}, 13 * kNsPerSecond);  // serves nothing now
  EXPECT_FALSE(c.contested("r1"));
}

TEST(ServingConflicts, OwnRobotsChangingFindTheConflictAndEveryPeerIsNamed) {
  ServingConflicts c(kSilentNs);
  c.on_peer_report("peer-a", "a", {"r1", "r2", "r3", "r4", "r5"}, 0);
  c.on_peer_report("peer-b", "b", {"r1"}, 0);
  EXPECT_FALSE(c.contested("r1"));  // it serves no robot yet
  c.set_own_robots({"r1", "r2", "r3", "r4", "r5"}, 0);
  EXPECT_EQ(c.contested_robots(), 5u);
  EXPECT_EQ(c.conflicts_found(), 6u);  // (r1, a), (r1, b), (r2..r5, a)
  EXPECT_EQ(c.describe(2), "robot r1 also served by a, b; robot r2 also served by a; and 3 more robot(s)");
  c.on_peer_gone("peer-a", 0);
  EXPECT_EQ(c.describe(), "robot r1 also served by b");
  c.on_peer_gone("peer-unknown", 0);  // a writer that never reported: nothing changes
  EXPECT_TRUE(c.contested("r1"));
}

// A localizer shard lost (its announcement's liveliness) takes its participant's peer ids with it:
// the Diagnostics of a killed process may go on listing its robots for seconds.
TEST(ServingConflicts, EveryPeerOfAParticipantGoneAtOnce) {
  ServingConflicts c(kSilentNs);
  c.set_own_robots({"r1"}, 0);
  c.on_peer_report("0102aa-diagnostics", "shard-1", {"r1"}, 0);
  c.on_peer_report("0103bb-diagnostics", "shard-2", {"r1"}, 0);
  ASSERT_EQ(c.describe(), "robot r1 also served by shard-1, shard-2");
  c.on_peers_gone("0102", 10);
  EXPECT_TRUE(c.contested("r1"));
  EXPECT_EQ(c.describe(), "robot r1 also served by shard-2");
  c.on_peers_gone("0103", 20);
  EXPECT_FALSE(c.contested("r1"));
}

}  // namespace
}  // namespace beaconloc
