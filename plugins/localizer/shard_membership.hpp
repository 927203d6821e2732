#pragma once
// A localizer shard's view of its peers (issue 19): the shards of the same estimator that are
// alive, and so which robots this one serves (ShardAssignment: rendezvous hashing, every shard
// deciding alone, no coordinator). DDS-free: a shard is an id (its announcement writer's), the
// participant adapter tells what DDS saw (an announcement, a writer lost or alive again), and
// times are the caller's steady clock.
//
// A shard that starts serves nothing for settle_ns: long enough to hear the shards already
// running (their announcements are kept for late joiners), so that it does not take, for a
// moment, robots that others serve. A shard alone after that serves every robot.
#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/shard_assignment.hpp"
#include "beaconloc/core/time.hpp"

namespace beaconloc {

// A joining shard's wait before it serves: the running shards' announcements come as soon as
// discovery matches it with them (loopback profile: announcements every 100 ms for the first
// 2 s, found within a few hundred ms even on a loaded machine).
inline constexpr StampNs kShardSettleNs = kNsPerSecond;

class ShardMembership {
 public:
  ShardMembership(std::string self_id, std::string estimator, StampNs started_ns, StampNs settle_ns);

  // A shard's announcement (heard again after a restart of its writer): counted live when it runs
  // the same estimator; a shard of another estimator serves its own robots, not a share of these.
  // Each returns whether the set of live shards changed (the robots served change with it).
  bool on_announcement(const std::string& shard_id, const std::string& estimator);
  // Its writer was lost (liveliness: died or hung) or left: its robots go to the others.
  bool on_shard_gone(const std::string& shard_id);
  // Its writer is alive again after a loss (a stall longer than the lease): it serves its share again.
  bool on_shard_alive(const std::string& shard_id);

  // Whether this shard serves the robot now: false while settling.
  bool serves(std::string_view robot_id, StampNs now_ns) const {
    return now_ns - started_ns_ >= settle_ns_ && assignment_.owns(robot_id);
  }
  bool settled(StampNs now_ns) const { return now_ns - started_ns_ >= settle_ns_; }
  std::size_t live_shards() const { return assignment_.live().size(); }
  const std::string& self() const { return assignment_.self(); }
  // The live shard serving robot_id (its id).
  const std::string& owner(std::string_view robot_id) const { return assignment_.owner(robot_id); }
  // Announcements of shards of another estimator, over the run (not a share of these robots).
  std::size_t other_estimator_shards() const { return other_estimator_; }

 private:
  struct Peer {
    bool same_estimator = false;
    bool alive = true;
  };
  bool update_live();

  std::string estimator_;
  StampNs started_ns_;
  StampNs settle_ns_;
  ShardAssignment assignment_;
  std::map<std::string, Peer> peers_;  // by shard id, every shard heard from (not itself)
  std::size_t other_estimator_ = 0;
};

}  // namespace beaconloc
