#pragma once
// Range measurement model: 3D distance from a receiver on the robot to a ceiling beacon
// (seed 000 eq. 2-3, general beacon height). Shared by every filter (EKF, IEKF, UKF, H-infinity)
// and by the range-only pose solver.
#include <Eigen/Core>
#include <optional>

#include "beaconloc/core/models/model_concepts.hpp"
#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

struct RangePrediction {
  double range_m = 0.0;
  Eigen::RowVector3d jacobian_pose = Eigen::RowVector3d::Zero();  // d range / d [x, y, yaw]
};

// receiver_base_m: the receiver in the frame of `pose` (seed 000 eq. 1), at height receiver_z_m.
RangePrediction predict_range(const Pose2& pose, const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                              const Eigen::Vector3d& beacon_map_m);

// States a range may be calibrated by: h = scale * d + bias, scale and bias read from the state
// at these indices (when given; otherwise scale 1 and bias 0, not in the state).
struct RangeCalibrationIndex {
  std::optional<Eigen::Index> scale;
  std::optional<Eigen::Index> bias_m;
};

// One range, receiver -> beacon, as a measurement model (core/models/model_concepts.hpp) on any
// state holding the pose at `pose`. Where the receiver is at the beacon the gradient is
// undefined and left zero (the filter's innovation covariance is then R alone).
class RangeModel {
 public:
  static constexpr int kSize = 1;
  static constexpr bool kHasJacobian = true;
  static constexpr bool kPlainResidual = true;  // z - h: no angle in z
  using Vector = Vec<1>;

  RangeModel(const Eigen::Vector2d& receiver_base_m, double receiver_z_m, const Eigen::Vector3d& beacon_map_m,
             double variance_m2, PoseIndex pose = {}, RangeCalibrationIndex calibration = {})
      : receiver_base_m_(receiver_base_m),
        receiver_z_m_(receiver_z_m),
        beacon_map_m_(beacon_map_m),
        variance_m2_(variance_m2),
        pose_(pose),
        calibration_(calibration) {}

  Eigen::Index size() const { return 1; }
  template <int N>
  Vector predict(const Vec<N>& x) const {
    return Vector(calibrated(x, geometry(x).range_m));
  }
  template <int N>
  MeasurementLinearization<1, N> linearize(const Vec<N>& x) const {
    const RangePrediction g = geometry(x);
    MeasurementLinearization<1, N> out;
    out.predicted(0) = calibrated(x, g.range_m);
    out.jacobian = Mat<1, N>::Zero(1, x.size());
    const double scale = calibration_.scale ? x(*calibration_.scale) : 1.0;
    const Eigen::Index at[3] = {pose_.x, pose_.y, pose_.yaw};
    for (int c = 0; c < 3; ++c) out.jacobian(0, at[c]) = calibration_.scale ? scale * g.jacobian_pose(c) : g.jacobian_pose(c);
    if (calibration_.scale) out.jacobian(0, *calibration_.scale) = g.range_m;
    if (calibration_.bias_m) out.jacobian(0, *calibration_.bias_m) = 1.0;
    return out;
  }
  Mat<1, 1> noise() const { return Mat<1, 1>(variance_m2_); }
  Vector residual(const Vector& z, const Vector& h) const { return z - h; }

 private:
  template <int N>
  RangePrediction geometry(const Vec<N>& x) const {
    return predict_range(pose_.pose_of(x), receiver_base_m_, receiver_z_m_, beacon_map_m_);
  }
  template <int N>
  double calibrated(const Vec<N>& x, double range_m) const {
    if (calibration_.scale) range_m *= x(*calibration_.scale);
    if (calibration_.bias_m) range_m += x(*calibration_.bias_m);
    return range_m;
  }
  Eigen::Vector2d receiver_base_m_;
  double receiver_z_m_;
  Eigen::Vector3d beacon_map_m_;
  double variance_m2_;
  PoseIndex pose_;
  RangeCalibrationIndex calibration_;
};

}  // namespace beaconloc
