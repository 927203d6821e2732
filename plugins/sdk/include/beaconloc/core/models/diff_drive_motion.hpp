#pragma once
// Differential-drive odometry motion model, seed 000 eq. 14 with its Jacobians eq. 16.
#include <Eigen/Core>

#include "beaconloc/core/models/model_concepts.hpp"
#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

struct DiffDrivePrediction {
  Pose2 pose;                                   // x_bar_k of eq. 14 (diff_drive_step: the pose given)
  Eigen::Matrix3d jacobian_pose;                // J_f,x of eq. 16
  Eigen::Matrix<double, 3, 2> jacobian_wheels;  // J_f,u of eq. 16, u = [v_R, v_L]
  Pose2 step;                                   // x_bar_k - x_k-1 (the heading step unwrapped)
};

// Eq. 14: Delta D = dT (v_R + v_L) / 2, Delta phi = dT (v_R - v_L) / B_w, the pose advanced along
// the mean heading phi + Delta phi / 2.
// J_f,u is the product printed in eq. 16, d f / d[Delta D, Delta phi] times
// d[Delta D, Delta phi] / d[v_R, v_L] = [[dT/2, dT/2], [dT/B_w, -dT/B_w]] (ERRATA: the copy
// prints the second factor with "R").
DiffDrivePrediction predict_diff_drive(const Pose2& pose, double wheel_velocity_right_mps,
                                       double wheel_velocity_left_mps, double wheel_base_m, double dt_s);
// Eq. 14 read backwards: the speeds [v_R, v_L] of wheels wheel_base_m apart on a robot moving at
// v and turning at omega, v +- omega B_w / 2 ...
inline Eigen::Vector2d wheel_speeds_mps(double v_mps, double omega_radps, double wheel_base_m) {
  const double half_track_m = wheel_base_m / 2.0;
  return {v_mps + omega_radps * half_track_m, v_mps - omega_radps * half_track_m};
}
// ... and that map's matrix, d[v_R, v_L] / d[v, omega] = [[1, B_w / 2], [1, -B_w / 2]], which
// carries a covariance of (v, omega) to the wheels.
inline Eigen::Matrix2d wheel_speeds_per_twist(double wheel_base_m) {
  Eigen::Matrix2d j;
  j << 1.0, wheel_base_m / 2.0, 1.0, -wheel_base_m / 2.0;
  return j;
}

// The same without the moved pose (pose is left as given): the step and the Jacobians, all a
// filter composing x (+) dx needs (it wraps the heading itself: one wrap, not two).
DiffDrivePrediction diff_drive_step(const Pose2& pose, double wheel_velocity_right_mps, double wheel_velocity_left_mps,
                                    double wheel_base_m, double dt_s);

// Eq. 14 and 16 as a motion model (core/models/model_concepts.hpp) on any state holding the pose
// at `pose`; the rest of the state stays. Input u = [v_R, v_L] (m/s), its noise U_k of eq. 16
// the wheel velocities' covariance.
class DiffDriveMotion {
 public:
  static constexpr int kInputSize = 2;
  static constexpr bool kHasStateNoise = false;
  using Input = Eigen::Vector2d;

  DiffDriveMotion(double wheel_base_m, const Eigen::Matrix2d& wheel_velocity_covariance, PoseIndex pose = {})
      : wheel_base_m_(wheel_base_m), covariance_(wheel_velocity_covariance), pose_(pose) {}

  template <int N>
  Vec<N> step(const Vec<N>& x, const Input& u, double dt_s) const {
    Vec<N> dx = Vec<N>::Zero(x.size());
    place(dx, diff_drive_step(pose_.pose_of(x), u(0), u(1), wheel_base_m_, dt_s).step);
    return dx;
  }
  template <int N>
  MotionLinearization<N, 2> linearize(const Vec<N>& x, const Input& u, double dt_s) const {
    const DiffDrivePrediction p = diff_drive_step(pose_.pose_of(x), u(0), u(1), wheel_base_m_, dt_s);
    MotionLinearization<N, 2> out;
    if constexpr (N == 3) {
      if (pose_.x == 0 && pose_.y == 1 && pose_.yaw == 2) {  // the state is the pose: eq. 16 as it is
        out.step = p.step;
        out.jacobian_state = p.jacobian_pose;
        out.jacobian_input = p.jacobian_wheels;
        return out;
      }
    }
    out.step = Vec<N>::Zero(x.size());
    place(out.step, p.step);
    out.jacobian_state = Mat<N, N>::Identity(x.size(), x.size());
    out.jacobian_input = Mat<N, 2>::Zero(x.size(), 2);
    const Eigen::Index at[3] = {pose_.x, pose_.y, pose_.yaw};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) out.jacobian_state(at[r], at[c]) = p.jacobian_pose(r, c);
      out.jacobian_input.row(at[r]) = p.jacobian_wheels.row(r);
    }
    return out;
  }
  Eigen::Matrix2d input_noise(const Input& /*u*/) const { return covariance_; }

 private:
  template <int N>
  void place(Vec<N>& dx, const Pose2& step) const {
    dx(pose_.x) = step.x();
    dx(pose_.y) = step.y();
    dx(pose_.yaw) = step.z();
  }
  double wheel_base_m_;
  Eigen::Matrix2d covariance_;
  PoseIndex pose_;
};

}  // namespace beaconloc
