#include "distance_prediction.hpp"

#include <cmath>

#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc::duhl {

Eigen::Vector2d ReceiverRing::receiver(int l) const {
  const double g = 2.0 * M_PI * l / 3.0;  // eq. 1
  return {radius_m * std::cos(g), radius_m * std::sin(g)};
}

namespace {

// C = r cos(theta), S = r sin(theta) from the distances, and their gradients.
struct BearingTerms {
  double c, s;
  Eigen::RowVector3d dc, ds;
};

BearingTerms bearing_terms(const Distances& q, double r_r) {
  BearingTerms t;
  t.c = -(2 * q(0) * q(0) - q(1) * q(1) - q(2) * q(2)) / (6.0 * r_r);
  t.s = (q(2) * q(2) - q(1) * q(1)) / (2.0 * std::sqrt(3.0) * r_r);
  t.dc << -4 * q(0) / (6.0 * r_r), 2 * q(1) / (6.0 * r_r), 2 * q(2) / (6.0 * r_r);
  t.ds << 0.0, -2 * q(1) / (2.0 * std::sqrt(3.0) * r_r), 2 * q(2) / (2.0 * std::sqrt(3.0) * r_r);
  return t;
}

}  // namespace

TxGeometry tx_geometry(const Distances& q, double z, const ReceiverRing& ring) {
  const double rho_sq = q.squaredNorm() / 3.0 - ring.radius_m * ring.radius_m;  // eq. 11
  const BearingTerms b = bearing_terms(q, ring.radius_m);
  return {std::sqrt(std::max(0.0, rho_sq - z * z)), std::atan2(b.s, b.c)};
}

DistancePrediction predict_distances(const Distances& q, double z, double v_r, double v_l,
                                     double wheel_base_m, double dt_s, const ReceiverRing& ring) {
  const double delta_d = dt_s * (v_r + v_l) / 2.0;  // eq. 14
  const double delta_phi = dt_s * (v_r - v_l) / wheel_base_m;
  const TxGeometry geo = tx_geometry(q, z, ring);
  const double r = geo.planar_range_m, theta = geo.bearing_rad;
  const BearingTerms b = bearing_terms(q, ring.radius_m);
  // d r / d q_m = q_m / (3 r); d theta / d q = (C dS - S dC) / (C^2 + S^2).
  const Eigen::RowVector3d dr =
      r > 1e-9 ? Eigen::RowVector3d(q.transpose() / (3.0 * r)) : Eigen::RowVector3d::Zero();
  const double cs_sq = b.c * b.c + b.s * b.s;
  const Eigen::RowVector3d dtheta =
      cs_sq > 1e-18 ? Eigen::RowVector3d((b.c * b.ds - b.s * b.dc) / cs_sq) : Eigen::RowVector3d::Zero();

  DistancePrediction out;
  Eigen::Matrix<double, 3, 2> d_g_d_increment;  // d g / d [Delta D, Delta phi]
  for (int l = 0; l < 3; ++l) {
    const Eigen::Vector2d rx = ring.receiver(l);
    const double half = delta_phi / 2.0;
    const double alpha = delta_d * (rx.x() * std::cos(half) + rx.y() * std::sin(half));
    const double lever = rx.x() * std::sin(theta) - rx.y() * std::cos(theta);
    const double bracket = delta_d * std::cos(theta - half) + delta_phi * lever;
    const double beta = r * bracket;
    out.q(l) = q(l) + (alpha - beta) / q(l);

    // J_g,q (eq. 24): d g_l / d q_m = delta_lm (1 - (alpha - beta) / q_l^2) - (1 / q_l) d beta_l / d q_m.
    const double dbeta_dr = bracket;
    const double dbeta_dtheta = r * (-delta_d * std::sin(theta - half) +
                                     delta_phi * (rx.x() * std::cos(theta) + rx.y() * std::sin(theta)));
    const Eigen::RowVector3d dbeta_dq = dbeta_dr * dr + dbeta_dtheta * dtheta;
    out.jacobian_q.row(l) = -dbeta_dq / q(l);
    out.jacobian_q(l, l) += 1.0 - (alpha - beta) / (q(l) * q(l));

    // J_g,u through the increments.
    const double dalpha_dd = rx.x() * std::cos(half) + rx.y() * std::sin(half);
    const double dalpha_dphi = delta_d * (-rx.x() * std::sin(half) + rx.y() * std::cos(half)) / 2.0;
    const double dbeta_dd = r * std::cos(theta - half);
    const double dbeta_dphi = r * (delta_d * std::sin(theta - half) / 2.0 + lever);
    d_g_d_increment(l, 0) = (dalpha_dd - dbeta_dd) / q(l);
    d_g_d_increment(l, 1) = (dalpha_dphi - dbeta_dphi) / q(l);
  }
  Eigen::Matrix2d d_increment_d_wheels;  // ERRATA, eq. 16
  d_increment_d_wheels << dt_s / 2.0, dt_s / 2.0, dt_s / wheel_base_m, -dt_s / wheel_base_m;
  out.jacobian_wheels = d_g_d_increment * d_increment_d_wheels;
  return out;
}

DistanceInit initial_distances(const Pose2& pose, const Cov3& pose_covariance,
                               const Eigen::Vector3d& tx_map_m, const ReceiverRing& ring) {
  DistanceInit out;
  for (int l = 0; l < 3; ++l) {  // eq. 28
    const RangePrediction p = predict_range(pose, ring.receiver(l), ring.height_m, tx_map_m);
    out.q(l) = p.range_m;
    out.jacobian_pose.row(l) = p.jacobian_pose;
  }
  out.covariance = out.jacobian_pose * pose_covariance * out.jacobian_pose.transpose();  // eq. 29
  return out;
}

}  // namespace beaconloc::duhl
