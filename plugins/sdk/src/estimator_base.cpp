#include "beaconloc/core/estimator_base.hpp"

namespace beaconloc {

std::optional<PoseEstimate> EstimatorBase::estimate() const {
  if (!has_pose_ || !now_ns()) return std::nullopt;
  const PoseBelief b = pose_belief();
  return PoseEstimate{*now_ns(), b.pose_map_base, b.covariance, status()};
}

PoseStatus EstimatorBase::status() const {
  if (!has_pose_) return PoseStatus::kInitializing;
  const PoseStatus s = staleness_.classify(now_ns().value_or(last_correction_ns_), last_correction_ns_);
  return suspect() && s == PoseStatus::kOk ? PoseStatus::kDegraded : s;
}

std::optional<StartupWait> EstimatorBase::startup_wait() const {
  if (estimate()) return std::nullopt;
  if (needs_beacon_map() && map_.empty()) return StartupWait{StartupCondition::kNoBeaconMap, 0.0, 0.0, {}};
  if (has_pose_) return StartupWait{StartupCondition::kNoOdometry, 0.0, 0.0, {}};
  return waiting_for();
}

InputResult EstimatorBase::reset(StampNs stamp_ns, const Pose2& pose, const Cov3& covariance) {
  if (const InputResult checked = check_initial_pose(pose, covariance); !checked.accepted) return checked;
  if (!place(pose, covariance)) return InputResult::rejected(Rejection::kResetUnsupported);
  start(now_ns().value_or(stamp_ns));
  return InputResult::ok();
}

}  // namespace beaconloc
