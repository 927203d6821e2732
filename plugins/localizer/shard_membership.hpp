#pragma once
// A localizer shard's view of its peers (issue 19): the shards of the same estimator that are
// alive, and so which robots this one serves (ShardAssignment: rendezvous hashing, every shard
// deciding alone, no coordinator). DDS-free: a shard is an id (its announcement writer's), the
// participant adapter tells what DDS saw (an announcement, a writer lost, alive again or gone
// for good), and times are the caller's steady clock.
//
// A shard that starts serves nothing until it has settled: it listens for settle_ns to the
// shards already running (their announcements are kept for late joiners); then the participant
// announces it and it serves its share from its first liveliness assertion, as the others hand
// that share over on hearing it (the two within the announcement's delivery). A shard alone
// after that serves every robot.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/shard_assignment.hpp"
#include "beaconloc/core/time.hpp"

namespace beaconloc {

// A joining shard's wait before it announces itself and serves: the running shards'
// announcements come as soon as discovery matches it with them (loopback profile:
// announcements every 100 ms for the first 2 s, found within a few hundred ms even on a loaded
// machine; through two discovery servers, every shard of 16 found within 0.13 s after this wait:
// BENCHMARKS.md, "Shards and discovery across hosts").
inline constexpr StampNs kShardSettleNs = kNsPerSecond;

class ShardMembership {
 public:
  ShardMembership(std::string self_id, std::string estimator, StampNs settle_ns);

  // Starts the settle time: once this shard can hear the others, and again after a stall past
  // its lease (the others took its robots; they hand them back when it is alive again). Serves
  // nothing until settled.
  void start_settling(StampNs now_ns) { settling_from_ns_ = now_ns; }
  bool settled(StampNs now_ns) const {
    return settling_from_ns_ && now_ns - *settling_from_ns_ >= settle_ns_;
  }

  enum class Announcement {
    kNoChange,          // its own, or a shard heard again
    kLiveSetChanged,    // the robots served change with it
    kEstimatorChanged,  // refused: a shard's estimator is the one it first announced
  };
  // A shard's announcement: counted live when it runs the same estimator. A shard of another
  // estimator is no peer: its fleet serves every robot too, which the serving-conflict check
  // reports (two localizers serving one robot).
  Announcement on_announcement(const std::string& shard_id, const std::string& estimator);
  // Its writer's liveliness was lost (died or hung): its robots go to the others. Each returns
  // whether the set of live shards changed.
  bool on_shard_lost(const std::string& shard_id);
  // Its writer is alive again after a loss (a stall longer than the lease): it serves its share again.
  bool on_shard_alive(const std::string& shard_id);
  // Its writer is gone for good (deleted, or its participant left or was dropped): forgotten.
  bool on_shard_gone(const std::string& shard_id);

  // Whether this shard serves the robot now: false until settled.
  bool serves(const std::string& robot_id, StampNs now_ns) const;
  std::size_t live_shards() const { return assignment_.live().size(); }
  std::size_t known_shards() const { return peers_.size(); }  // live or lost, this one not counted
  const std::string& self() const { return assignment_.self(); }
  // The live shard serving robot_id (its id).
  const std::string& owner(std::string_view robot_id) const { return assignment_.owner(robot_id); }
  // Shards of another estimator heard (not a share of these robots).
  std::size_t other_estimator_shards() const;

 private:
  struct Peer {
    std::string estimator;
    bool alive = true;
  };
  bool update_live();

  std::string estimator_;
  StampNs settle_ns_;
  std::optional<StampNs> settling_from_ns_;
  ShardAssignment assignment_;
  std::map<std::string, Peer> peers_;  // by shard id, every shard heard from and not gone (not itself)
  // Whether it owns each robot asked about, for the live set in force: one lookup per sample
  // instead of a hash per live shard. Cleared when the set changes, and when it outgrows
  // kOwnsCacheMax (robot ids never seen again: a fleet that renamed its robots, a hostile stream).
  static constexpr std::size_t kOwnsCacheMax = 4096;
  mutable std::unordered_map<std::string, bool> owns_cache_;
};

}  // namespace beaconloc
