#include "shard_membership.hpp"

#include <utility>

namespace beaconloc {

ShardMembership::ShardMembership(std::string self_id, std::string estimator, StampNs settle_ns)
    : estimator_(std::move(estimator)), settle_ns_(settle_ns), assignment_(std::move(self_id)) {}

ShardMembership::Announcement ShardMembership::on_announcement(const std::string& shard_id,
                                                               const std::string& estimator) {
  if (shard_id == assignment_.self()) return Announcement::kNoChange;  // its own, come back to its reader
  auto [it, first] = peers_.try_emplace(shard_id, Peer{estimator, true});
  if (!first && it->second.estimator != estimator) return Announcement::kEstimatorChanged;
  it->second.alive = true;
  return update_live() ? Announcement::kLiveSetChanged : Announcement::kNoChange;
}

bool ShardMembership::on_shard_lost(const std::string& shard_id) {
  const auto it = peers_.find(shard_id);
  if (it == peers_.end()) return false;
  it->second.alive = false;
  return update_live();
}

bool ShardMembership::on_shard_alive(const std::string& shard_id) {
  const auto it = peers_.find(shard_id);
  if (it == peers_.end()) return false;  // not announced yet: its announcement will come
  it->second.alive = true;
  return update_live();
}

bool ShardMembership::on_shard_gone(const std::string& shard_id) {
  if (peers_.erase(shard_id) == 0) return false;
  return update_live();
}

bool ShardMembership::serves(const std::string& robot_id, StampNs now_ns) const {
  if (!settled(now_ns)) return false;
  if (const auto it = owns_cache_.find(robot_id); it != owns_cache_.end()) return it->second;
  if (owns_cache_.size() >= kOwnsCacheMax) owns_cache_.clear();
  return owns_cache_.emplace(robot_id, assignment_.owns(robot_id)).first->second;
}

std::size_t ShardMembership::other_estimator_shards() const {
  std::size_t n = 0;
  for (const auto& [id, peer] : peers_) n += peer.estimator != estimator_;
  return n;
}

bool ShardMembership::update_live() {
  std::vector<std::string> live;
  for (const auto& [id, peer] : peers_) {
    if (peer.alive && peer.estimator == estimator_) live.push_back(id);
  }
  if (!assignment_.set_live(std::move(live))) return false;
  owns_cache_.clear();
  return true;
}

}  // namespace beaconloc
