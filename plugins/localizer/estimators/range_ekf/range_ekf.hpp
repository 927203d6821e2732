#pragma once
// range_ekf: EKF on [x, y, yaw], predicted by wheel odometry (seed 000 eq. 14, 16) and updated
// by each range on its own (3D range from a receiver to a ceiling beacon of known height), with
// NIS gating. Initialized, and re-initialized after a run of gated ranges, by a global
// range-only fix (core/solvers/range_pose_solver) over a window of ranges, each moved to the
// current pose through the dead-reckoned odometry.
#include <deque>
#include <optional>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/filters/ekf.hpp"
#include "beaconloc/core/odometry_timeline.hpp"

namespace beaconloc {

struct RangeEkfParameters {
  double nis_gate = 10.83;     // chi-square, 1 dof, 99.9 %
  double init_window_s = 3.0;  // ranges kept for a global fix
  int init_min_beacons = 3;
  int init_min_ranges = 8;  // ranges (after the echo screen) a global fix needs: 3 unknowns + 5
  // Beacons all on one line leave the mirror image of the pose as good a fit: a global fix
  // waits until the beacons heard spread this far across their principal axis (RMS).
  double init_min_beacon_spread_m = 0.2;
  double init_max_position_sigma_m = 0.3;
  double init_max_yaw_sigma_rad = 0.35;
  double max_odometry_gap_s = 0.2;  // a longer gap is not integrated (reason odometry_gap)
  double wheel_velocity_variance_floor_m2ps2 = 1e-6;
  int reinitialize_after_gated = 15;   // 5 slots x 3 receivers refused in a row: lost
  double max_range_age_s = 0.6;        // ranges older than the newest odometry by more: stale
  double init_retry_interval_s = 0.5;  // data time between two attempts at a global fix
  // A range of the window more than this many sigma off the global fix is dropped as an echo
  // (up to 40 % of them); 0 keeps every range.
  double init_outlier_gate_sigma = 4.0;

  static RangeEkfParameters from(const EstimatorConfig& config);
};

class RangeEkf final : public Estimator {
 public:
  explicit RangeEkf(const EstimatorConfig& config);
  std::string name() const override { return "range_ekf"; }
  void set_beacon_map(const BeaconMap& map) override { map_ = map; }
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  InputResult reset(StampNs stamp_ns, const Pose2& pose_map_base, const Cov3& covariance) override;
  std::optional<PoseEstimate> estimate() const override;
  PoseStatus status() const override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<RangeEkf>(*this); }

 private:
  struct BufferedRange {
    RangeMeasurement range;
    Pose2 odom_pose_at_range;
  };
  InputResult fuse(const RangeMeasurement& range);
  void try_initialize();

  ReceiverArray receivers_;
  RangeEkfParameters params_;
  StalenessPolicy staleness_;
  BeaconMap map_;
  Ekf<3> ekf_;
  bool initialized_ = false;
  OdometryTimeline timeline_;
  StampNs last_correction_stamp_ns_ = 0;
  Pose2 odom_pose_ = Pose2::Zero();  // dead-reckoned, odometry frame
  std::deque<BufferedRange> window_;
  int consecutive_gated_ = 0;
  std::optional<StampNs> last_init_attempt_ns_;
};

}  // namespace beaconloc
