// Seed 004's receiver geometry: eq. 11 (pose from the two receivers) exact for any mounting, eq. 12
// (its covariance) against a Monte Carlo of the receivers' errors and against the paper's
// statement for its mounting (heading variance n^T V n / (2 l^2)), and the receiver's odometry
// step against finite differences of the diff-drive pose step.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "two_receiver_ekf/receiver_pair.hpp"

namespace beaconloc {
namespace {

TEST(ReceiverPair, Equation11RecoversThePoseForAnyMounting) {
  for (const ReceiverPair& pair : {ReceiverPair{{0.133, 0.0}, {-0.133, 0.0}}, ReceiverPair{{0.3, 0.1}, {-0.05, -0.2}}}) {
    for (const Pose2& truth : {Pose2(1.0, 2.0, 0.3), Pose2(-4.0, 0.5, -2.9), Pose2(0.0, 0.0, M_PI)}) {
      const PairPose p = pose_from_receivers(transform_point(truth, pair.front_base_m), Eigen::Matrix2d::Identity(),
                                             transform_point(truth, pair.rear_base_m), Eigen::Matrix2d::Identity(), pair);
      EXPECT_LT((p.pose_map_base.head<2>() - truth.head<2>()).norm(), 1e-12);
      EXPECT_LT(std::abs(wrap_angle_rad(p.pose_map_base.z() - truth.z())), 1e-12);
    }
  }
}

TEST(ReceiverPair, Equation12IsThePapersFormForItsMountingAndMatchesMonteCarloForAnyOther) {
  const double l = 0.133;
  const ReceiverPair paper{{l, 0.0}, {-l, 0.0}};
  const Pose2 truth(1.0, 1.0, 0.4);
  const Eigen::Matrix2d v = (Eigen::Matrix2d() << 4e-4, 1e-4, 1e-4, 2e-4).finished();
  const PairPose p = pose_from_receivers(transform_point(truth, paper.front_base_m), v,
                                         transform_point(truth, paper.rear_base_m), v, paper);
  const Eigen::Vector2d n(-std::sin(truth.z()), std::cos(truth.z()));  // normal to the robot's axis
  EXPECT_NEAR(p.covariance(2, 2), n.dot(v * n) / (2.0 * l * l), 1e-12);
  EXPECT_LT((p.covariance.topLeftCorner<2, 2>() - v / 2.0).norm(), 1e-12);

  // An offset mounting and unequal covariances, against 200000 draws.
  const ReceiverPair odd{{0.3, 0.1}, {-0.05, -0.2}};
  const Eigen::Matrix2d vf = (Eigen::Matrix2d() << 1e-4, 2e-5, 2e-5, 3e-4).finished();
  const Eigen::Matrix2d vr = (Eigen::Matrix2d() << 5e-4, -1e-4, -1e-4, 1e-4).finished();
  const Eigen::Vector2d pf = transform_point(truth, odd.front_base_m), pr = transform_point(truth, odd.rear_base_m);
  const PairPose analytic = pose_from_receivers(pf, vf, pr, vr, odd);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const Eigen::Matrix2d lf = vf.llt().matrixL(), lr = vr.llt().matrixL();
  Cov3 sampled = Cov3::Zero();
  const int n_draws = 200000;
  for (int i = 0; i < n_draws; ++i) {
    const Eigen::Vector2d ef = lf * Eigen::Vector2d(normal(rng), normal(rng));
    const Eigen::Vector2d er = lr * Eigen::Vector2d(normal(rng), normal(rng));
    const PairPose drawn = pose_from_receivers(pf + ef, vf, pr + er, vr, odd);
    Eigen::Vector3d e = drawn.pose_map_base - truth;
    e.z() = wrap_angle_rad(e.z());
    sampled += e * e.transpose() / n_draws;
  }
  EXPECT_LT((sampled - analytic.covariance).cwiseAbs().maxCoeff(), 0.03 * analytic.covariance.cwiseAbs().maxCoeff())
      << "sampled\n" << sampled << "\nanalytic\n" << analytic.covariance;
}

TEST(ReceiverPair, TheReceiversStepIsWhereTheDiffDriveStepPutsItAndItsCovarianceIsTheLinearizedOne) {
  const Eigen::Vector2d b(0.133, 0.05);
  const Pose2 pose(1.0, 2.0, 0.7);
  const double right = 0.25, left = 0.15, base = 0.3, dt = 0.01;
  const ReceiverStep s = receiver_step(pose, 0.0, b, right, left, Eigen::Matrix2d::Zero(), base, dt);
  const Pose2 moved = predict_diff_drive(pose, right, left, base, dt).pose;
  EXPECT_LT((s.displacement_m - (transform_point(moved, b) - transform_point(pose, b))).norm(), 1e-14);
  EXPECT_TRUE(s.covariance.isZero());
  // Covariance = G U G^T + g var(yaw) g^T with G, g the displacement's derivatives: numerically.
  const auto displacement = [&](const Pose2& p, double r, double l) {
    return receiver_step(p, 0.0, b, r, l, Eigen::Matrix2d::Zero(), base, dt).displacement_m;
  };
  const double h = 1e-6;
  Eigen::Matrix2d g;
  g.col(0) = (displacement(pose, right + h, left) - displacement(pose, right - h, left)) / (2 * h);
  g.col(1) = (displacement(pose, right, left + h) - displacement(pose, right, left - h)) / (2 * h);
  const Eigen::Vector2d gy = (displacement(pose + Pose2(0, 0, h), right, left) - displacement(pose - Pose2(0, 0, h), right, left)) / (2 * h);
  const Eigen::Matrix2d u = (Eigen::Matrix2d() << 1e-3, 2e-4, 2e-4, 5e-4).finished();
  const ReceiverStep noisy = receiver_step(pose, 0.01, b, right, left, u, base, dt);
  const Eigen::Matrix2d expected = g * u * g.transpose() + 0.01 * gy * gy.transpose();
  EXPECT_LT((noisy.covariance - expected).cwiseAbs().maxCoeff(), 1e-9 + 1e-6 * expected.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace beaconloc
