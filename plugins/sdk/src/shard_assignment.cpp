#include "beaconloc/core/shard_assignment.hpp"

#include <algorithm>
#include <utility>

namespace beaconloc {

namespace {
constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325ULL;
constexpr std::uint64_t kFnvPrime = 0x100000001b3ULL;

std::uint64_t fnv1a(std::uint64_t h, std::string_view bytes) {
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= kFnvPrime;
  }
  return h;
}

// splitmix64's finalizer: FNV-1a alone leaves the high bits of similar ids (robot-1, robot-2)
// close, which would give one shard a run of them.
std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
}  // namespace

ShardAssignment::ShardAssignment(std::string self) : self_(std::move(self)), live_{self_} {}

bool ShardAssignment::set_live(std::vector<std::string> shards) {
  shards.push_back(self_);
  std::sort(shards.begin(), shards.end());
  shards.erase(std::unique(shards.begin(), shards.end()), shards.end());
  if (shards == live_) return false;
  live_ = std::move(shards);
  return true;
}

std::uint64_t ShardAssignment::weight(std::string_view shard, std::string_view robot_id) {
  // The shard's bytes, a separator no id holds apart from its end, then the robot's: ("ab", "c")
  // and ("a", "bc") hash apart.
  std::uint64_t h = fnv1a(kFnvOffset, shard);
  h = fnv1a(h, std::string_view("\0", 1));
  return mix(fnv1a(h, robot_id));
}

const std::string& ShardAssignment::owner(std::string_view robot_id) const {
  const std::string* best = &live_.front();
  std::uint64_t best_weight = weight(*best, robot_id);
  for (std::size_t i = 1; i < live_.size(); ++i) {
    const std::uint64_t w = weight(live_[i], robot_id);
    // Ties (2^-64) go to the smaller id, so every shard breaks them alike.
    if (w > best_weight) {
      best = &live_[i];
      best_weight = w;
    }
  }
  return *best;
}

}  // namespace beaconloc
