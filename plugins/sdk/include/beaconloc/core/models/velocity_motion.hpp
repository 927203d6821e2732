#pragma once
// The velocity motion model of seed 001 eq. 10-11 (Thrun et al.'s): the robot moves on an arc
// with translational velocity v and rotational velocity omega for dt; and the velocity noise
// of eq. 6, variances alpha_1 v^2 + alpha_2 omega^2 and alpha_3 v^2 + alpha_4 omega^2.
#include <array>

#include "beaconloc/core/models/model_concepts.hpp"
#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

// Eq. 10-11 as a step [dx, dy, dyaw] from `pose` (the heading step omega dt unwrapped), with its
// Jacobians d(pose + step)/d pose and d step / d[v, omega]. |omega| below 1e-9 rad/s is the
// straight-line limit (ERRATA: omega -> 0 handled explicitly, where v / omega would divide by
// zero), its Jacobians the limits of the arc's.
struct VelocityStep {
  Pose2 step;
  Eigen::Matrix3d jacobian_pose;
  Eigen::Matrix<double, 3, 2> jacobian_velocity;
};
VelocityStep velocity_step(const Pose2& pose, double v_mps, double omega_radps, double dt_s);

// Eq. 10-11: the pose moved by velocity_step, its heading wrapped.
Pose2 predict_velocity_motion(const Pose2& pose, double v_mps, double omega_radps, double dt_s);

// Eq. 6: the diagonal of M, the variances of the noise on (v, omega).
Eigen::Vector2d velocity_noise_variance(double v_mps, double omega_radps, const std::array<double, 4>& alpha);

// Eq. 6 and 10-11 as a motion model (core/models/model_concepts.hpp) on any state holding the
// pose at `pose`. Input u = [v, omega]; its noise M of eq. 6, each variance floored at
// kMinVariance so that a robot at rest keeps a positive-definite augmented covariance.
class VelocityMotion {
 public:
  static constexpr int kInputSize = 2;
  static constexpr bool kHasStateNoise = false;
  static constexpr double kMinVariance = 1e-12;
  using Input = Eigen::Vector2d;

  explicit VelocityMotion(const std::array<double, 4>& alpha, PoseIndex pose = {}) : alpha_(alpha), pose_(pose) {}

  template <int N>
  Vec<N> step(const Vec<N>& x, const Input& u, double dt_s) const {
    Vec<N> dx = Vec<N>::Zero(x.size());
    const Pose2 s = velocity_step(pose_.pose_of(x), u(0), u(1), dt_s).step;
    dx(pose_.x) = s.x();
    dx(pose_.y) = s.y();
    dx(pose_.yaw) = s.z();
    return dx;
  }
  template <int N>
  MotionLinearization<N, 2> linearize(const Vec<N>& x, const Input& u, double dt_s) const {
    const VelocityStep s = velocity_step(pose_.pose_of(x), u(0), u(1), dt_s);
    MotionLinearization<N, 2> out;
    out.step = Vec<N>::Zero(x.size());
    out.jacobian_state = Mat<N, N>::Identity(x.size(), x.size());
    out.jacobian_input = Mat<N, 2>::Zero(x.size(), 2);
    const Eigen::Index at[3] = {pose_.x, pose_.y, pose_.yaw};
    for (int r = 0; r < 3; ++r) {
      out.step(at[r]) = s.step(r);
      for (int c = 0; c < 3; ++c) out.jacobian_state(at[r], at[c]) = s.jacobian_pose(r, c);
      out.jacobian_input.row(at[r]) = s.jacobian_velocity.row(r);
    }
    return out;
  }
  Eigen::Matrix2d input_noise(const Input& u) const {
    return velocity_noise_variance(u(0), u(1), alpha_).cwiseMax(kMinVariance).asDiagonal();
  }

 private:
  std::array<double, 4> alpha_;
  PoseIndex pose_;
};

}  // namespace beaconloc
