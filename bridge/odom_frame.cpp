#include "odom_frame.hpp"

#include <cmath>

#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/odometry_timeline.hpp"

namespace beaconloc::bridge {

bool OdomFrame::push(StampNs stamp_ns, const Pose2& pose) {
  if (!poses_.empty() && stamp_ns <= poses_.back().first) return false;
  poses_.emplace_back(stamp_ns, pose);
  while (poses_.size() > 2 && poses_.front().first < stamp_ns - history_ns_) poses_.pop_front();
  return true;
}

InputResult OdomFrame::add_wheel_odometry(const OdometrySample& o) {
  // The estimators' checks and time line (core/odometry_timeline.hpp): an absurd speed integrated
  // here would put odom -> base_link, and the twist the bridge publishes, at infinity; a gap is
  // not integrated (the velocities describe only the last period) but re-anchors the frame where
  // it was, so that a clock that steps forward does not freeze it.
  const OdometryTimeline::Step step = timeline_.advance(o);
  const bool gap = !step.result.accepted && step.result.rejection == Rejection::kOdometryGap;
  if (!step.result.accepted && !gap) return step.result;
  Pose2 pose = poses_.empty() ? Pose2::Zero() : poses_.back().second;
  if (step.integrate) {
    pose = predict_diff_drive(pose, o.wheel_velocity_right_mps, o.wheel_velocity_left_mps, o.wheel_base_m,
                              step.dt_s)
               .pose;
  }
  // At most 10 m/s for 200 ms a sample: beyond a site's extent only after days of driving.
  if (!within_site(pose)) return InputResult::rejected(Rejection::kImplausibleOdomPose);
  v_mps_ = (o.wheel_velocity_right_mps + o.wheel_velocity_left_mps) / 2.0;
  omega_radps_ = (o.wheel_velocity_right_mps - o.wheel_velocity_left_mps) / o.wheel_base_m;
  // d[v, omega] / d[v_R, v_L] = [[1/2, 1/2], [1/B_w, -1/B_w]] (the inverse of
  // wheel_speeds_per_twist): Cov(v, omega) = J Cov(v_R, v_L) J^T, written out so that it is exactly
  // symmetric (a matrix product rounds its two off-diagonal entries differently).
  const double var_right = o.wheel_velocity_covariance(0, 0), cross = o.wheel_velocity_covariance(0, 1),
               var_left = o.wheel_velocity_covariance(1, 1), base_m = o.wheel_base_m;
  const double cov_v_omega = (var_right - var_left) / (2.0 * base_m);
  twist_covariance_ << (var_right + 2.0 * cross + var_left) / 4.0, cov_v_omega, cov_v_omega,
      (var_right - 2.0 * cross + var_left) / (base_m * base_m);
  push(o.stamp_ns, pose);
  return step.result;  // accepted, or odometry_gap (taken, not integrated)
}

bool OdomFrame::within_site(const Pose2& pose) {
  return pose.allFinite() && pose.head<2>().cwiseAbs().maxCoeff() <= kMaxMapCoordinateM &&
         std::abs(pose.z()) <= kMaxAngleRad;
}

bool OdomFrame::add_odom_pose(StampNs stamp_ns, const Pose2& pose, double v_mps, double omega_radps,
                              const Eigen::Matrix2d& twist_covariance) {
  if (!within_site(pose) || !std::isfinite(v_mps) || !std::isfinite(omega_radps) || !twist_covariance.allFinite() ||
      !push(stamp_ns, pose))
    return false;
  v_mps_ = v_mps;
  omega_radps_ = omega_radps;
  twist_covariance_ = twist_covariance;
  return true;
}

std::optional<Pose2> OdomFrame::pose_odom_base(StampNs stamp_ns) const {
  if (poses_.empty() || stamp_ns < poses_.front().first || stamp_ns > poses_.back().first)
    return std::nullopt;
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    if (poses_[i].first < stamp_ns) continue;
    const auto& [t0, p0] = poses_[i - 1];
    const auto& [t1, p1] = poses_[i];
    const double a = static_cast<double>(stamp_ns - t0) / static_cast<double>(t1 - t0);
    Pose2 p = p0 + a * (p1 - p0);
    p.z() = wrap_angle_rad(p0.z() + a * wrap_angle_rad(p1.z() - p0.z()));
    return p;
  }
  return poses_.back().second;  // stamp_ns equals the only sample's
}

std::optional<Pose2> OdomFrame::pose_map_odom(StampNs stamp_ns, const Pose2& pose_map_base) const {
  const auto odom_base = pose_odom_base(stamp_ns);
  if (!odom_base) return std::nullopt;
  return compose(pose_map_base, between(*odom_base, Pose2::Zero()));  // T_map_base * T_odom_base^-1
}

}  // namespace beaconloc::bridge
