#pragma once
// Hyperbolic measurements (seed 003 eq. 27): the range to each beacon of a group minus the range
// to the group's first beacon, from one receiver, on any state holding the pose. The differences
// share the first beacon's range error, so their noise is correlated (eq. 19, ERRATA: sigma^2 on
// the diagonal, sigma^2 / 2 off it, sigma^2 the variance of one difference).
#include <stdexcept>
#include <vector>

#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc {

class RangeDifferenceModel {
 public:
  static constexpr int kSize = Eigen::Dynamic;
  static constexpr bool kHasJacobian = true;
  static constexpr bool kPlainResidual = true;  // z - h: no angle in z
  using Vector = Eigen::VectorXd;

  // beacons_map_m: the reference beacon first, then one beacon per difference (at least two in
  // all; throws std::invalid_argument otherwise). difference_variance_m2: sigma_vT^2 of eq. 19.
  RangeDifferenceModel(const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                       std::vector<Eigen::Vector3d> beacons_map_m, double difference_variance_m2,
                       PoseIndex pose = {})
      : receiver_base_m_(receiver_base_m),
        receiver_z_m_(receiver_z_m),
        beacons_(std::move(beacons_map_m)),
        variance_m2_(difference_variance_m2),
        pose_(pose) {
    if (beacons_.size() < 2) throw std::invalid_argument("RangeDifferenceModel: a reference and one more beacon");
  }

  Eigen::Index size() const { return static_cast<Eigen::Index>(beacons_.size()) - 1; }
  template <int N>
  Vector predict(const Vec<N>& x) const {
    return linearize(x).predicted;
  }
  template <int N>
  MeasurementLinearization<Eigen::Dynamic, N> linearize(const Vec<N>& x) const {
    const Pose2 pose = pose_.pose_of(x);
    const RangePrediction ref = predict_range(pose, receiver_base_m_, receiver_z_m_, beacons_[0]);
    MeasurementLinearization<Eigen::Dynamic, N> out;
    out.predicted.resize(size());
    out.jacobian = Mat<Eigen::Dynamic, N>::Zero(size(), x.size());
    const Eigen::Index at[3] = {pose_.x, pose_.y, pose_.yaw};
    for (Eigen::Index i = 0; i < size(); ++i) {
      const RangePrediction r = predict_range(pose, receiver_base_m_, receiver_z_m_, beacons_[i + 1]);
      out.predicted(i) = r.range_m - ref.range_m;  // eq. 27
      for (int c = 0; c < 3; ++c) out.jacobian(i, at[c]) = r.jacobian_pose(c) - ref.jacobian_pose(c);
    }
    return out;
  }
  // Eq. 19.
  Eigen::MatrixXd noise() const {
    Eigen::MatrixXd r = Eigen::MatrixXd::Constant(size(), size(), 0.5 * variance_m2_);
    r.diagonal().setConstant(variance_m2_);
    return r;
  }
  Vector residual(const Vector& z, const Vector& h) const { return z - h; }

 private:
  Eigen::Vector2d receiver_base_m_;
  double receiver_z_m_;
  std::vector<Eigen::Vector3d> beacons_;
  double variance_m2_;
  PoseIndex pose_;
};

}  // namespace beaconloc
