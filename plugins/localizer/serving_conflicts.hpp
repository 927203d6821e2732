#pragma once
// Two localizers serving one robot, found without reading each other's poses: each lists the
// robots it serves in its Diagnostics (1 Hz) and reads the others' reports. A robot this
// localizer serves that a live peer serves too is contested: its poses go out degraded, never
// ok (a consumer cannot trust a stream that mixes two estimators), and the Diagnostics name the
// robot and the peer, until the peer stops serving it, stops, or falls silent. DDS-free: a peer
// is an id (its writer) and a name (its participant); times are the caller's steady clock.
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"

namespace beaconloc {

class ServingConflicts {
 public:
  // A peer not heard from for silent_after_ns is taken for gone (dds::kDiagnosticsSilentAfter).
  explicit ServingConflicts(StampNs silent_after_ns) : silent_after_ns_(silent_after_ns) {}

  // The robots this localizer serves (any order); the conflicts are found again.
  void set_own_robots(const std::vector<std::string>& robots, StampNs now_ns);
  // A peer's report of the robots it serves, heard at now_ns.
  void on_peer_report(const std::string& peer, const std::string& name,
                      const std::vector<std::string>& robots, StampNs now_ns);
  // The peer stopped, or DDS lost it.
  void on_peer_gone(const std::string& peer, StampNs now_ns);
  // Every peer whose id begins with prefix is gone (its participant died: a localizer shard's
  // loss is known from its announcement's liveliness long before its Diagnostics fall silent).
  void on_peers_gone(const std::string& prefix, StampNs now_ns);
  // Drops the peers silent at now_ns (call now and then: the Diagnostics period).
  void refresh(StampNs now_ns);

  bool contested(const std::string& robot) const { return conflicts_.count(robot) != 0; }
  // The status to publish a robot's pose with: ok becomes degraded while the robot is contested.
  PoseStatus status_of(const std::string& robot, PoseStatus status) const;
  std::size_t contested_robots() const { return conflicts_.size(); }
  // (robot, peer) conflicts that began, over the run: each counted once when it starts.
  std::uint64_t conflicts_found() const { return found_; }
  // "robot r1 also served by NAME[, NAME]; ..." for the first max_robots robots, "" when none.
  std::string describe(std::size_t max_robots = 3) const;

 private:
  struct Peer {
    std::string name;
    std::set<std::string> robots;
    StampNs heard_ns = 0;
  };
  void find_conflicts(StampNs now_ns);

  StampNs silent_after_ns_;
  std::set<std::string> own_;
  std::map<std::string, Peer> peers_;                       // by id
  std::map<std::string, std::set<std::string>> conflicts_;  // robot -> peer ids
  std::uint64_t found_ = 0;
};

}  // namespace beaconloc
