#pragma once
// The lifecycle every estimator shares (issue 14): the beacon map, the odometry time line, the
// staleness policy, and from them status(), estimate(), startup_wait() and reset(). An estimator
// derives from EstimatorBase and keeps only its maths: where its pose is (pose_belief), when it
// has one (start / forget_pose) and was last corrected (corrected), what it waits for before its
// first pose (waiting_for), and how it is placed by hand (place).
#include <optional>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/odometry_timeline.hpp"

namespace beaconloc {

class EstimatorBase : public Estimator {
 public:
  void set_beacon_map(const BeaconMap& map) override { map_ = map; }
  // Stamped with the newest odometry; nullopt without a pose or before the first odometry sample.
  std::optional<PoseEstimate> estimate() const final;
  // Initializing without a pose; then by the data time since the last correction
  // (StalenessPolicy), degraded while suspect().
  PoseStatus status() const final;
  // nullopt with a pose; else no beacon map (for an estimator that needs one), no odometry (a
  // pose but no time line yet), or what waiting_for() says.
  std::optional<StartupWait> startup_wait() const final;
  // A checked pose (check_initial_pose), placed by place() and corrected at the estimator's own
  // time (its newest odometry; stamp_ns before the first); reset_unsupported when place() refuses.
  InputResult reset(StampNs stamp_ns, const Pose2& pose_map_base, const Cov3& covariance) final;

 protected:
  explicit EstimatorBase(double max_odometry_gap_s) : timeline_(max_odometry_gap_s) {}

  struct PoseBelief {
    Pose2 pose_map_base;
    Cov3 covariance;
  };
  // The pose and its covariance; asked only while has_pose().
  virtual PoseBelief pose_belief() const = 0;
  // Why there is no pose yet, once the common conditions (map, odometry) are met.
  virtual StartupWait waiting_for() const = 0;
  // Take this checked pose as the belief; false for an estimator that cannot be placed.
  virtual bool place(const Pose2& /*pose_map_base*/, const Cov3& /*covariance*/) { return false; }
  // The recent measurements contradict the pose: an ok pose shows degraded.
  virtual bool suspect() const { return false; }
  // Whether the estimator waits for a beacon map before anything else.
  virtual bool needs_beacon_map() const { return true; }

  // The pose is known, corrected at correction_ns.
  void start(StampNs correction_ns) {
    has_pose_ = true;
    last_correction_ns_ = correction_ns;
  }
  void forget_pose() { has_pose_ = false; }
  void corrected(StampNs correction_ns) { last_correction_ns_ = correction_ns; }
  bool has_pose() const { return has_pose_; }
  // The estimator's time: its newest odometry stamp.
  std::optional<StampNs> now_ns() const { return timeline_.last_stamp_ns(); }
  OdometryTimeline::Step advance(const OdometrySample& o) { return timeline_.advance(o); }
  // The longest odometry interval integrated now (OdometryTimeline::gap_limit_s).
  double odometry_gap_limit_s() const { return timeline_.gap_limit_s(); }
  const BeaconMap& map() const { return map_; }

 private:
  BeaconMap map_;
  OdometryTimeline timeline_;
  StalenessPolicy staleness_;
  bool has_pose_ = false;
  StampNs last_correction_ns_ = 0;
};

}  // namespace beaconloc
