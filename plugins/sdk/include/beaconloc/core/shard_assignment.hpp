#pragma once
// Which localizer shard serves a robot, decided by every shard on its own from the set of live
// shards, with no coordinator (issue 19): rendezvous (highest random weight) hashing. Each robot
// goes to the live shard whose hash of (shard, robot) is highest, so every shard that sees the
// same set agrees on every robot; a shard that dies moves only its own robots, spread over the
// others; a shard that joins takes about 1/n of the robots, each from the shard that had it.
// DDS-free; the hash is this file's own (FNV-1a over the bytes as unsigned, then a 64-bit mix),
// the same on every host and build, so that shards of different builds or machines agree.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace beaconloc {

class ShardAssignment {
 public:
  // self: this shard's id, unique among the shards (its announcement writer's GUID, as text:
  // ShardMembership); live from the start.
  explicit ShardAssignment(std::string self);

  // The live shards as now known, any order: self is always among them (none given: itself
  // alone), repeats are one. Returns whether the set changed.
  bool set_live(std::vector<std::string> shards);
  const std::vector<std::string>& live() const { return live_; }  // sorted
  const std::string& self() const { return self_; }

  // The live shard that serves robot_id.
  const std::string& owner(std::string_view robot_id) const;
  bool owns(std::string_view robot_id) const { return owner(robot_id) == self_; }

  // The weight of (shard, robot): the robot goes to the live shard where it is highest.
  static std::uint64_t weight(std::string_view shard, std::string_view robot_id);

 private:
  std::string self_;
  std::vector<std::string> live_;
};

}  // namespace beaconloc
