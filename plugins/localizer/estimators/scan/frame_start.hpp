#pragma once
// Seed 003 Sec. 3.2-3.3, Fig. 5 and 7: a frame's first pose from two of its group's fixes
// (group_fix.hpp): the position from the newer, the heading from the direction between them.
// The paper takes two consecutive positions, which assumes the robot drove straight between
// them; here the odometry between the two fixes is tracked (from the older one, in the robot's
// frame there) and its own turn and sidestep taken out, so a fix pair on a curve gives the
// heading too. The covariance is the fixes' and the odometry's, propagated to first order.
#include <optional>

#include "beaconloc/core/filters/ekf.hpp"
#include "beaconloc/core/measurements.hpp"
#include "scan/group_fix.hpp"

namespace beaconloc::scan {

struct FrameStartSettings {
  // The robot must have moved this far (odometry) from the first fix before a second gives the
  // heading (and the fixes' chord be at least half of it): the heading's sigma is about the fixes'
  // sigma (1-5 cm under a 1 m group at 3.5 m) times 1.4 over it. Not in the paper ("a second
  // different MR position"). Must be > 0 (FrameStart throws std::invalid_argument otherwise).
  double heading_baseline_m = 1.0;
  // Two fixes whose distance the odometry contradicts by more than this many sigmas: the older
  // is dropped (an echo moved it) and the newer starts again.
  double max_disagreement_sigma = 4.0;
};

struct FrameBelief {
  Pose2 pose_frame_base = Pose2::Zero();
  Cov3 covariance = Cov3::Identity();
};

enum class FrameStartWait : std::uint8_t {
  kNoFix,             // no fix of the group yet
  kTooShortBaseline,  // a fix, and the robot has not moved heading_baseline_m from it yet
};

class FrameStart {
 public:
  explicit FrameStart(const FrameStartSettings& settings);
  // The odometry since the first fix (before it nothing is tracked, and kApplied is returned).
  PredictResult predict(const OdometrySample& odometry, double dt_s, double wheel_variance_floor_m2ps2);
  // A new fix of the group (ok() only): the frame's first pose once two fixes are far enough apart.
  std::optional<FrameBelief> add_fix(const GroupFix& fix);
  FrameStartWait waiting_for() const { return first_ ? FrameStartWait::kTooShortBaseline : FrameStartWait::kNoFix; }
  // How far the robot is from where it was at the first fix (odometry), 0 without one.
  double displacement_m() const;

 private:
  FrameStartSettings settings_;
  std::optional<GroupFix> first_;
  Ekf<3> odometry_since_first_{pose_space()};  // the robot's pose in its frame at the first fix
};

}  // namespace beaconloc::scan
