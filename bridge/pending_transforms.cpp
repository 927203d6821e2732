#include "pending_transforms.hpp"

namespace beaconloc::bridge {

PendingTransforms::Added PendingTransforms::add(const PoseEstimate& estimate) {
  if (!waiting_.empty() && waiting_.back().stamp_ns == estimate.stamp_ns) {
    waiting_.back() = estimate;
    return Added::kReplacedWaiting;
  }
  if (last_published_ns_ && estimate.stamp_ns == *last_published_ns_) return Added::kAlreadyPublished;
  Added added = Added::kQueued;
  if (waiting_.size() >= capacity_) {
    waiting_.pop_front();
    added = Added::kQueuedDroppedOldest;
  }
  waiting_.push_back(estimate);
  return added;
}

std::vector<PoseEstimate> PendingTransforms::take_reached(StampNs newest_odometry_ns) {
  std::vector<PoseEstimate> reached;
  while (!waiting_.empty() && waiting_.front().stamp_ns <= newest_odometry_ns) {
    reached.push_back(waiting_.front());
    waiting_.pop_front();
  }
  return reached;
}

}  // namespace beaconloc::bridge
