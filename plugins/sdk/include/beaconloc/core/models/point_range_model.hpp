#pragma once
// Range from a tracked point to a ceiling beacon (seed 004 eq. 4-1): the state holds the point's
// planar position [x, y] (a receiver tracked on its own), at a known height z_c;
// h = sqrt((x - x_i)^2 + (y - y_i)^2 + (z_c - z_i)^2). The measurement model the seed 004 EKFs
// share with every filter (core/models/model_concepts.hpp).
#include <Eigen/Core>

#include "beaconloc/core/models/model_concepts.hpp"

namespace beaconloc {

// Where the point sits in a state: the indices of its x_m and y_m.
struct PointIndex {
  Eigen::Index x = 0;
  Eigen::Index y = 1;
};

class PointRangeModel {
 public:
  static constexpr int kSize = 1;
  static constexpr bool kHasJacobian = true;
  static constexpr bool kPlainResidual = true;  // z - h: no angle in z
  using Vector = Vec<1>;

  PointRangeModel(double point_z_m, const Eigen::Vector3d& beacon_map_m, double variance_m2, PointIndex at = {})
      : point_z_m_(point_z_m), beacon_map_m_(beacon_map_m), variance_m2_(variance_m2), at_(at) {}

  Eigen::Index size() const { return 1; }
  template <int N>
  Vector predict(const Vec<N>& x) const {
    return Vector(offset(x).norm());
  }
  // Seed 004 eq. 9 (H = [(x - x_i) / D, (y - y_i) / D], D the predicted range). Where the point
  // is at the beacon the gradient is undefined and left zero (S is then R alone).
  template <int N>
  MeasurementLinearization<1, N> linearize(const Vec<N>& x) const {
    const Eigen::Vector3d d = offset(x);
    const double range_m = d.norm();
    MeasurementLinearization<1, N> out;
    out.predicted(0) = range_m;
    out.jacobian = Mat<1, N>::Zero(1, x.size());
    if (range_m > 0.0) {
      out.jacobian(0, at_.x) = d.x() / range_m;
      out.jacobian(0, at_.y) = d.y() / range_m;
    }
    return out;
  }
  Mat<1, 1> noise() const { return Mat<1, 1>(variance_m2_); }
  Vector residual(const Vector& z, const Vector& h) const { return z - h; }

 private:
  template <int N>
  Eigen::Vector3d offset(const Vec<N>& x) const {
    return Eigen::Vector3d(x(at_.x), x(at_.y), point_z_m_) - beacon_map_m_;
  }
  double point_z_m_;
  Eigen::Vector3d beacon_map_m_;
  double variance_m2_;
  PointIndex at_;
};

}  // namespace beaconloc
