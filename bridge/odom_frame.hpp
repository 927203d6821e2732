#pragma once
// The robot's pose in its odometry frame over the last seconds, so that the bridge can publish
// map -> odom (REP-105) for a pose estimate: T_map_odom = T_map_base * T_odom_base^-1 at the
// estimate's stamp. The odom -> base pose comes from the robot's driver (nav_msgs/Odometry) when
// it feeds us, else from integrating the wheel odometry on the bus. DDS-free.
#include <deque>
#include <optional>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/odometry_timeline.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/pose2.hpp"

namespace beaconloc::bridge {

class OdomFrame {
 public:
  explicit OdomFrame(StampNs history_ns = 2'000'000'000) : history_ns_(history_ns), timeline_(kMaxIntegratedGapS) {}
  // Integrates wheel velocities (eq. 14 of seed 000) from the previous sample; the first sample
  // anchors the frame at the origin. Checked as the estimators check odometry (OdometryTimeline):
  // refused with their reasons (implausible_wheel_speed, out_of_order_odometry, ...), or
  // implausible_odom_pose beyond a site's extent; a gap (over kMaxIntegratedGapS, or what a
  // slower sensor's own period allows: OdometryTimeline) is taken without integrating it (the
  // frame stays where it was) and reported as odometry_gap.
  InputResult add_wheel_odometry(const OdometrySample& o);
  // The estimators' default max_odometry_gap_s.
  static constexpr double kMaxIntegratedGapS = kDefaultMaxOdometryGapS;
  // A driver's own odom -> base pose (finite, within a site's extent), its finite twist and the
  // twist's covariance as the driver stated it (finite, variances >= 0: from_ros_odometry checks).
  bool add_odom_pose(StampNs stamp_ns, const Pose2& pose_odom_base, double v_mps, double omega_radps,
                     const Eigen::Matrix2d& twist_covariance);
  // odom -> base at stamp_ns, interpolated between neighbours; nullopt outside the history.
  std::optional<Pose2> pose_odom_base(StampNs stamp_ns) const;
  // map -> odom from a pose estimate stamped stamp_ns.
  std::optional<Pose2> pose_map_odom(StampNs stamp_ns, const Pose2& pose_map_base) const;
  // The newest stamp of the history, if any.
  std::optional<StampNs> latest_stamp_ns() const {
    return poses_.empty() ? std::nullopt : std::optional<StampNs>(poses_.back().first);
  }
  // The latest wheel odometry's twist (v, omega), for nav_msgs/Odometry, and its covariance over
  // (v, omega): the wheel speeds' reported covariance carried through v = (v_R + v_L) / 2,
  // omega = (v_R - v_L) / B_w, or the driver's own. Before any odometry, the twist is unknown:
  // (0, 0) with kUnknownTwistVariance on the diagonal, not a certain standstill.
  double v_mps() const { return v_mps_; }
  double omega_radps() const { return omega_radps_; }
  const Eigen::Matrix2d& twist_covariance() const { return twist_covariance_; }
  // A variance that says "not known" (robot_localization's advice for unmeasured quantities: a
  // large one), (m/s)^2 and (rad/s)^2: 1000 m/s and rad/s of standard deviation.
  static constexpr double kUnknownTwistVariance = 1e6;

 private:
  bool push(StampNs stamp_ns, const Pose2& pose);
  static bool within_site(const Pose2& pose);
  StampNs history_ns_;
  OdometryTimeline timeline_;  // of the wheel odometry (add_wheel_odometry)
  std::deque<std::pair<StampNs, Pose2>> poses_;
  double v_mps_ = 0.0;
  double omega_radps_ = 0.0;
  Eigen::Matrix2d twist_covariance_ = kUnknownTwistVariance * Eigen::Matrix2d::Identity();
};

}  // namespace beaconloc::bridge
