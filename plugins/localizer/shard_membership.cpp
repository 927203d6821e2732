#include "shard_membership.hpp"

#include <utility>

namespace beaconloc {

ShardMembership::ShardMembership(std::string self_id, std::string estimator, StampNs started_ns, StampNs settle_ns)
    : estimator_(std::move(estimator)),
      started_ns_(started_ns),
      settle_ns_(settle_ns),
      assignment_(std::move(self_id)) {}

bool ShardMembership::on_announcement(const std::string& shard_id, const std::string& estimator) {
  if (shard_id == assignment_.self()) return false;  // its own, come back to its reader
  auto [it, first] = peers_.try_emplace(shard_id);
  it->second.same_estimator = estimator == estimator_;
  it->second.alive = true;
  if (first && !it->second.same_estimator) ++other_estimator_;
  return update_live();
}

bool ShardMembership::on_shard_gone(const std::string& shard_id) {
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

bool ShardMembership::update_live() {
  std::vector<std::string> live;
  for (const auto& [id, peer] : peers_) {
    if (peer.alive && peer.same_estimator) live.push_back(id);
  }
  return assignment_.set_live(std::move(live));
}

}  // namespace beaconloc
