#include "distance_prediction.hpp"

#include <array>
#include <cmath>

#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/receiver_array.hpp"

namespace beaconloc::duhl {

Eigen::Vector2d ReceiverRing::receiver(int l) const {
  // Eq. 1, g_l = 2 pi (l-1) / 3: the cosines and sines computed once (every prediction of every
  // Tx's distances asks for the three receivers).
  static const std::array<Eigen::Vector2d, 3> unit = [] {
    std::array<Eigen::Vector2d, 3> u;
    for (int k = 0; k < 3; ++k) {
      const double g = 2.0 * M_PI * k / 3.0;
      u[k] = {std::cos(g), std::sin(g)};
    }
    return u;
  }();
  return {radius_m * unit[l].x(), radius_m * unit[l].y()};
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

// sqrt((rho^i)^2 - z_T^2), rho^i from eq. 11.
double planar_range(const Distances& q, double z, const ReceiverRing& ring) {
  const double rho_sq = q.squaredNorm() / 3.0 - ring.radius_m * ring.radius_m;  // eq. 11
  return std::sqrt(std::max(0.0, rho_sq - z * z));
}

}  // namespace

TxGeometry tx_geometry(const Distances& q, double z, const ReceiverRing& ring) {
  const BearingTerms b = bearing_terms(q, ring.radius_m);
  return {planar_range(q, z, ring), std::atan2(b.s, b.c)};
}

DistancePrediction predict_distances(const Distances& q, double z, double v_r, double v_l,
                                     double wheel_base_m, double dt_s, const ReceiverRing& ring) {
  const double delta_d = dt_s * (v_r + v_l) / 2.0;  // eq. 14
  const double delta_phi = dt_s * (v_r - v_l) / wheel_base_m;
  const BearingTerms b = bearing_terms(q, ring.radius_m);
  const double r = planar_range(q, z, ring);
  // d r / d q_m = q_m / (3 r); d theta / d q = (C dS - S dC) / (C^2 + S^2).
  const Eigen::RowVector3d dr =
      r > 1e-9 ? Eigen::RowVector3d(q.transpose() / (3.0 * r)) : Eigen::RowVector3d::Zero();
  const double cs_sq = b.c * b.c + b.s * b.s;
  const Eigen::RowVector3d dtheta =
      cs_sq > 1e-18 ? Eigen::RowVector3d((b.c * b.ds - b.s * b.dc) / cs_sq) : Eigen::RowVector3d::Zero();

  DistancePrediction out;
  Eigen::Matrix<double, 3, 2> d_g_d_increment;  // d g / d [Delta D, Delta phi]
  // The angles are the same for the three receivers: their sines and cosines, once. The bearing
  // theta = atan2(S, C) (tx_geometry) enters only through them: cos(theta) = C / sqrt(C^2 + S^2),
  // sin(theta) = S / sqrt(C^2 + S^2) (theta = 0 where C = S = 0, as atan2(0, 0) gives), and
  // theta - Delta phi / 2 by the angle-difference identities.
  const double half = delta_phi / 2.0;
  const double cos_half = std::cos(half), sin_half = std::sin(half);
  const double cs_norm = std::sqrt(cs_sq);
  const double cos_theta = cs_norm > 0.0 ? b.c / cs_norm : 1.0,
               sin_theta = cs_norm > 0.0 ? b.s / cs_norm : 0.0;
  const double cos_theta_half = cos_theta * cos_half + sin_theta * sin_half;
  const double sin_theta_half = sin_theta * cos_half - cos_theta * sin_half;
  for (int l = 0; l < 3; ++l) {
    const Eigen::Vector2d rx = ring.receiver(l);
    const double alpha = delta_d * (rx.x() * cos_half + rx.y() * sin_half);
    const double lever = rx.x() * sin_theta - rx.y() * cos_theta;
    const double bracket = delta_d * cos_theta_half + delta_phi * lever;
    const double beta = r * bracket;
    out.q(l) = q(l) + (alpha - beta) / q(l);

    // J_g,q (eq. 24): d g_l / d q_m = delta_lm (1 - (alpha - beta) / q_l^2) - (1 / q_l) d beta_l / d q_m.
    const double dbeta_dr = bracket;
    const double dbeta_dtheta =
        r * (-delta_d * sin_theta_half + delta_phi * (rx.x() * cos_theta + rx.y() * sin_theta));
    const Eigen::RowVector3d dbeta_dq = dbeta_dr * dr + dbeta_dtheta * dtheta;
    out.jacobian_q.row(l) = -dbeta_dq / q(l);
    out.jacobian_q(l, l) += 1.0 - (alpha - beta) / (q(l) * q(l));

    // J_g,u through the increments.
    const double dalpha_dd = rx.x() * cos_half + rx.y() * sin_half;
    const double dalpha_dphi = delta_d * (-rx.x() * sin_half + rx.y() * cos_half) / 2.0;
    const double dbeta_dd = r * cos_theta_half;
    const double dbeta_dphi = r * (delta_d * sin_theta_half / 2.0 + lever);
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

bool possible_distances(const Distances& d, double variance_m2, const ReceiverRing& ring) {
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      const double separation_m = (ring.receiver(a) - ring.receiver(b)).norm();
      if (!ranges_of_one_firing_agree(d(a), d(b), separation_m, 2.0 * variance_m2)) return false;
    }
  }
  return true;
}

bool explains_distances(const std::vector<TxBelief>& txs, const Pose2& pose, const Cov3& pose_covariance,
                        const ReceiverRing& ring, double gate_sigma) {
  for (const TxBelief& tx : txs) {
    const DistanceInit expected = initial_distances(pose, pose_covariance, tx.tx_map_m, ring);
    for (int l = 0; l < 3; ++l) {
      const double sigmas =
          std::abs(tx.q(l) - expected.q(l)) / std::sqrt(tx.covariance(l, l) + expected.covariance(l, l));
      if (!(sigmas <= gate_sigma)) return false;  // a non-finite residual does not explain
    }
  }
  return true;
}

}  // namespace beaconloc::duhl
