#pragma once
// Pose estimates waiting for their map -> odom transform: T_map_odom needs the odom -> base pose
// at the estimate's stamp, which arrives with the robot's odometry, often after the estimate.
// A pose at the stamp of the previous one is that pose corrected by a range (the localizer
// publishes corrections at once): it replaces a pose still waiting, and one whose transform is
// already out is dropped, since tf2 keeps the first transform at a stamp and warns of a repeat
// (TF_REPEATED_DATA); the next pose, 10 ms later, carries the correction. DDS-free.
#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

#include "beaconloc/core/estimator.hpp"

namespace beaconloc::bridge {

class PendingTransforms {
 public:
  enum class Added {
    kQueued,
    kReplacedWaiting,     // a correction of the pose still waiting at that stamp
    kAlreadyPublished,    // a correction of a pose whose transform is out: dropped
    kQueuedDroppedOldest  // queued; the oldest was given up (no odometry for `capacity` poses)
  };
  explicit PendingTransforms(std::size_t capacity = 100) : capacity_(capacity) {}
  Added add(const PoseEstimate& estimate);
  // The poses whose stamp the odometry has reached (<= newest_odometry_ns), oldest first;
  // they leave the queue.
  std::vector<PoseEstimate> take_reached(StampNs newest_odometry_ns);
  // The transform at this stamp went out.
  void published(StampNs stamp_ns) { last_published_ns_ = stamp_ns; }
  std::size_t size() const { return waiting_.size(); }

 private:
  std::size_t capacity_;
  std::deque<PoseEstimate> waiting_;
  std::optional<StampNs> last_published_ns_;
};

}  // namespace beaconloc::bridge
