#pragma once
// A pose observed directly: the UHL fix of seed 000 (eq. 17-21, J_h,x = I on the pose), on any
// state holding the pose. The residual wraps the heading.
#include "beaconloc/core/models/model_concepts.hpp"
#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

class PoseObservationModel {
 public:
  static constexpr int kSize = 3;
  static constexpr bool kHasJacobian = true;
  using Vector = Vec<3>;

  explicit PoseObservationModel(const Cov3& covariance, PoseIndex pose = {}) : r_(covariance), pose_(pose) {}

  Eigen::Index size() const { return 3; }
  template <int N>
  Vector predict(const Vec<N>& x) const {
    return pose_.pose_of(x);
  }
  template <int N>
  MeasurementLinearization<3, N> linearize(const Vec<N>& x) const {
    MeasurementLinearization<3, N> out;
    out.predicted = pose_.pose_of(x);
    out.jacobian = Mat<3, N>::Zero(3, x.size());
    out.jacobian(0, pose_.x) = 1.0;
    out.jacobian(1, pose_.y) = 1.0;
    out.jacobian(2, pose_.yaw) = 1.0;
    return out;
  }
  Cov3 noise() const { return r_; }
  Vector residual(const Vector& z, const Vector& h) const { return pose_difference(z, h); }

 private:
  Cov3 r_;
  PoseIndex pose_;
};

}  // namespace beaconloc
