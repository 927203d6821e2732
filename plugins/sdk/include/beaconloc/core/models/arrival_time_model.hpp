#pragma once
// The arrival time of one beacon's pulse at the robot (seed 002 eq. 17-21): the beacon fires at
// t0 and the pulse meets a robot moving at speed v along its heading theta, with the speed of
// sound s in the state:
//   t_i = t0 + d_i / (s - v (cos theta, sin theta) . u_i)                       (eq. 21)
// d_i the distance robot -> beacon (eq. 17) and u_i its unit vector (eq. 18). The copy is planar;
// here d_i is 3D (ceiling beacon, receiver at receiver_z_m at the robot's origin) and u_i the 3D
// unit vector, whose horizontal part the velocity meets; with beacon and receiver at one height it
// is eq. 21 as printed. The Jacobian is derived from eq. 21 (ERRATA: eq. 23 is its x component;
// the others are derived here and checked against a numeric one in tests/unit/filter_models_test).
// Times are seconds from an epoch the estimator chooses (t0 and z share it).
#include <cmath>

#include "beaconloc/core/models/model_concepts.hpp"

namespace beaconloc {

// Where eq. 21's unknowns sit in the state.
struct ArrivalTimeIndex {
  Eigen::Index x = 0;
  Eigen::Index y = 1;
  Eigen::Index speed = 2;    // v, m/s
  Eigen::Index heading = 3;  // theta, rad
  Eigen::Index fire_time = 5;       // t0, s
  Eigen::Index speed_of_sound = 6;  // s, m/s
};

class ArrivalTimeModel {
 public:
  static constexpr int kSize = 1;
  static constexpr bool kHasJacobian = true;
  static constexpr bool kPlainResidual = true;  // z - h: no angle in z
  using Vector = Vec<1>;

  ArrivalTimeModel(const Eigen::Vector3d& beacon_map_m, double receiver_z_m, double variance_s2,
                   ArrivalTimeIndex at = {})
      : beacon_map_m_(beacon_map_m), receiver_z_m_(receiver_z_m), variance_s2_(variance_s2), at_(at) {}

  Eigen::Index size() const { return 1; }
  template <int N>
  Vector predict(const Vec<N>& x) const {
    return linearize(x).predicted;
  }
  template <int N>
  MeasurementLinearization<1, N> linearize(const Vec<N>& x) const {
    const Eigen::Vector3d delta(x(at_.x) - beacon_map_m_.x(), x(at_.y) - beacon_map_m_.y(),
                                receiver_z_m_ - beacon_map_m_.z());
    const double d = delta.norm();  // eq. 17
    const Eigen::Vector3d u = d > 0.0 ? Eigen::Vector3d(delta / d) : Eigen::Vector3d::Zero();  // eq. 18
    const double v = x(at_.speed), c = std::cos(x(at_.heading)), s = std::sin(x(at_.heading));
    const double along = c * u.x() + s * u.y();       // (cos theta, sin theta) . u
    const double g = x(at_.speed_of_sound) - v * along;  // the pulse's closing speed
    MeasurementLinearization<1, N> out;
    out.predicted(0) = x(at_.fire_time) + d / g;  // eq. 21
    out.jacobian = Mat<1, N>::Zero(1, x.size());
    const double g2 = g * g;
    if (d > 0.0) {
      // d(d/g)/dx = u_x / g - d (dg/dx) / g^2, dg/dx = -v d(along)/dx, d(u)/dx = (e_x - u_x u) / d.
      out.jacobian(0, at_.x) = u.x() / g + v * (c * (1.0 - u.x() * u.x()) - s * u.x() * u.y()) / g2;
      out.jacobian(0, at_.y) = u.y() / g + v * (s * (1.0 - u.y() * u.y()) - c * u.x() * u.y()) / g2;
    }
    out.jacobian(0, at_.speed) = d * along / g2;
    out.jacobian(0, at_.heading) = d * v * (-s * u.x() + c * u.y()) / g2;
    out.jacobian(0, at_.fire_time) = 1.0;
    out.jacobian(0, at_.speed_of_sound) = -d / g2;
    return out;
  }
  Mat<1, 1> noise() const { return Mat<1, 1>(variance_s2_); }
  Vector residual(const Vector& z, const Vector& h) const { return z - h; }

 private:
  Eigen::Vector3d beacon_map_m_;
  double receiver_z_m_;
  double variance_s2_;
  ArrivalTimeIndex at_;
};

}  // namespace beaconloc
