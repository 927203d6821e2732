// Dynamic distance estimation (seed 000, Section IV): eq. 23 against the exact geometry
// (ERRATA), and the analytic Jacobians of eq. 24 and eq. 29 against numeric ones.
#include <gtest/gtest.h>

#include <cmath>

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "duhl/distance_prediction.hpp"

namespace beaconloc::duhl {
namespace {

const ReceiverRing kRing{0.19, 0.0};

Distances exact(const Pose2& pose, const Eigen::Vector3d& tx) {
  Distances q;
  for (int l = 0; l < 3; ++l) {
    const Eigen::Vector2d r = transform_point(pose, kRing.receiver(l));
    q(l) = Eigen::Vector3d(tx.x() - r.x(), tx.y() - r.y(), tx.z()).norm();
  }
  return q;
}

struct Case {
  Pose2 pose;
  Eigen::Vector3d tx;
  double v_r, v_l;
};

const std::vector<Case> kCases = {
    {{0.0, 0.0, 0.0}, {1.5, 0.5, 2.011}, 0.34, 0.34},   {{1.0, -0.5, 2.0}, {0.0, 0.0, 2.011}, 0.40, 0.28},
    {{2.0, 1.0, -2.5}, {3.0, 1.5, 1.887}, 1.05, 0.99},  {{-1.0, 2.0, 0.7}, {-1.2, 2.1, 2.011}, 0.2, -0.2},
    {{0.5, 0.5, 3.0}, {4.0, -2.0, 2.011}, -0.3, -0.25},
};

TEST(DuhlDistances, GeometryFromTheDistancesIsTheTxsRangeAndBearing) {
  for (const auto& c : kCases) {
    const TxGeometry g = tx_geometry(exact(c.pose, c.tx), c.tx.z(), kRing);
    const Eigen::Vector2d d = c.tx.head<2>() - c.pose.head<2>();
    EXPECT_NEAR(g.planar_range_m, d.norm(), 1e-9);
    EXPECT_NEAR(wrap_angle_rad(g.bearing_rad - (std::atan2(d.y(), d.x()) - c.pose.z())), 0.0, 1e-9);
  }
}

TEST(DuhlDistances, PredictionMatchesTheExactGeometryToFirstOrder) {
  // ERRATA, eq. 23: q + (alpha - beta) / q is the first-order form of the distance after the
  // receiver moved by the odometry increment; the rest is second order in the 10 ms step.
  for (const auto& c : kCases) {
    const double dt = 0.01, base = 0.33;
    const Pose2 moved = predict_diff_drive(c.pose, c.v_r, c.v_l, base, dt).pose;
    const Distances predicted =
        predict_distances(exact(c.pose, c.tx), c.tx.z(), c.v_r, c.v_l, base, dt, kRing).q;
    const Distances truth = exact(moved, c.tx);
    const double step = std::max(std::abs(c.v_r), std::abs(c.v_l)) * dt;
    EXPECT_LT((predicted - truth).cwiseAbs().maxCoeff(), 2.0 * step * step + 1e-12)
        << predicted.transpose() << " vs " << truth.transpose();
    // And the prediction moved the distances by the right first-order amount.
    EXPECT_LT((predicted - truth).norm(), 0.05 * (truth - exact(c.pose, c.tx)).norm() + 1e-9);
  }
}

TEST(DuhlDistances, DistanceJacobianMatchesNumeric) {
  for (const auto& c : kCases) {
    const Distances q = exact(c.pose, c.tx);
    const auto p = predict_distances(q, c.tx.z(), c.v_r, c.v_l, 0.33, 0.01, kRing);
    for (int m = 0; m < 3; ++m) {
      const double h = 1e-6;
      Distances hi = q, lo = q;
      hi(m) += h;
      lo(m) -= h;
      const Distances numeric = (predict_distances(hi, c.tx.z(), c.v_r, c.v_l, 0.33, 0.01, kRing).q -
                                 predict_distances(lo, c.tx.z(), c.v_r, c.v_l, 0.33, 0.01, kRing).q) /
                                (2 * h);
      EXPECT_LT((p.jacobian_q.col(m) - numeric).cwiseAbs().maxCoeff(), 1e-7) << "column " << m;
    }
  }
}

TEST(DuhlDistances, WheelJacobianMatchesNumeric) {
  for (const auto& c : kCases) {
    const Distances q = exact(c.pose, c.tx);
    const auto p = predict_distances(q, c.tx.z(), c.v_r, c.v_l, 0.33, 0.01, kRing);
    const double h = 1e-6;
    const Distances d_right = (predict_distances(q, c.tx.z(), c.v_r + h, c.v_l, 0.33, 0.01, kRing).q -
                               predict_distances(q, c.tx.z(), c.v_r - h, c.v_l, 0.33, 0.01, kRing).q) /
                              (2 * h);
    const Distances d_left = (predict_distances(q, c.tx.z(), c.v_r, c.v_l + h, 0.33, 0.01, kRing).q -
                              predict_distances(q, c.tx.z(), c.v_r, c.v_l - h, 0.33, 0.01, kRing).q) /
                             (2 * h);
    EXPECT_LT((p.jacobian_wheels.col(0) - d_right).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_LT((p.jacobian_wheels.col(1) - d_left).cwiseAbs().maxCoeff(), 1e-8);
  }
}

TEST(DuhlDistances, InitializationJacobianMatchesNumeric) {
  for (const auto& c : kCases) {
    const Cov3 p = Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal();
    const DistanceInit init = initial_distances(c.pose, p, c.tx, kRing);
    EXPECT_LT((init.q - exact(c.pose, c.tx)).norm(), 1e-12);  // eq. 28
    for (int j = 0; j < 3; ++j) {
      const double h = 1e-6;
      Pose2 hi = c.pose, lo = c.pose;
      hi(j) += h;
      lo(j) -= h;
      const Distances numeric = (exact(hi, c.tx) - exact(lo, c.tx)) / (2 * h);
      EXPECT_LT((init.jacobian_pose.col(j) - numeric).cwiseAbs().maxCoeff(), 1e-8);
    }
    EXPECT_TRUE(init.covariance.isApprox(init.jacobian_pose * p * init.jacobian_pose.transpose()));  // eq. 29
  }
}

}  // namespace
}  // namespace beaconloc::duhl
