// The generic EKF: against a textbook linear Kalman filter, gating, singular innovations.
#include "beaconloc/core/filters/ekf.hpp"
#include "beaconloc/core/models/linear_model.hpp"
#include "beaconloc/core/models/linear_motion.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

namespace beaconloc {
namespace {

TEST(Ekf, LinearUpdateMatchesKalmanFilter) {
  Ekf<3> ekf;
  Eigen::Vector3d x0(1.0, -2.0, 0.5);
  Eigen::Matrix3d p0;
  p0 << 0.5, 0.1, 0.0, 0.1, 0.3, 0.05, 0.0, 0.05, 0.2;
  ekf.reset(x0, p0);
  Eigen::Matrix<double, 2, 3> h;
  h << 1.0, 0.5, 0.0, 0.0, -1.0, 2.0;
  Eigen::Matrix2d r;
  r << 0.04, 0.01, 0.01, 0.09;
  const Eigen::Vector2d z(1.4, -0.3);
  const Eigen::Vector2d nu = z - h * x0;
  const auto result = ekf.update(LinearModel<2, 3>(h, r), z, 1e9);
  ASSERT_EQ(result.outcome, FilterOutcome::kApplied);

  // Textbook: K = P H^T S^-1, x = x + K nu, P = (I - K H) P.
  const Eigen::Matrix2d s = h * p0 * h.transpose() + r;
  const Eigen::Matrix<double, 3, 2> k = p0 * h.transpose() * s.inverse();
  const Eigen::Vector3d x_expected = x0 + k * nu;
  const Eigen::Matrix3d p_expected = (Eigen::Matrix3d::Identity() - k * h) * p0;
  EXPECT_TRUE(ekf.state().isApprox(x_expected, 1e-12));
  EXPECT_TRUE(ekf.covariance().isApprox(p_expected, 1e-12));
  EXPECT_NEAR(result.nis, nu.dot(s.inverse() * nu), 1e-12);
}

TEST(Ekf, PredictPropagatesCovariance) {
  Ekf<3> ekf;
  ekf.reset(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity());
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 2) = 0.3;
  const Eigen::Matrix3d q = 0.01 * Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 1> b(0.1, 0.0, 1.0);
  const auto predicted =
      ekf.predict(LinearMotion<3, 1>(f, b, Mat<1, 1>(0.04), q), Vec<1>(2.0), 0.01);
  ASSERT_TRUE(predicted.applied());
  EXPECT_TRUE(ekf.covariance().isApprox(f * f.transpose() + 0.04 * b * b.transpose() + q, 1e-12));
  EXPECT_TRUE(ekf.state().isApprox(Eigen::Vector3d(0.2, 0.0, 2.0), 1e-15));
}

TEST(Ekf, GatesOutliersAndLeavesTheStateAlone) {
  Ekf<3> ekf;
  ekf.reset(Eigen::Vector3d::Zero(), 0.01 * Eigen::Matrix3d::Identity());
  const Eigen::Matrix<double, 1, 3> h(1.0, 0.0, 0.0);
  const Eigen::Matrix<double, 1, 1> r(0.01);
  const auto result = ekf.update(LinearModel<1, 3>(h, r), Vec<1>(1.0), 10.83);
  EXPECT_EQ(result.outcome, FilterOutcome::kGated);
  EXPECT_NEAR(result.nis, 1.0 / 0.02, 1e-9);
  EXPECT_NEAR(result.log_det_s, std::log(0.02), 1e-12);  // S = P + R, a scalar: its own factor
  EXPECT_EQ(ekf.state(), Eigen::Vector3d::Zero());
}

// What update() would judge, without the update: the innovation and H P H^T (its NIS against
// them is update()'s); an unusable measurement gives none.
TEST(Ekf, PriorInnovationIsWhatTheUpdateSeesAndChangesNothing) {
  Ekf<3> ekf;
  ekf.reset(Eigen::Vector3d(0.2, 0.0, 0.0), 0.01 * Eigen::Matrix3d::Identity());
  const LinearModel<1, 3> model(Eigen::Matrix<double, 1, 3>(1.0, 0.5, 0.0), Mat<1, 1>(0.04));
  const auto prior = ekf.prior_innovation(model, Vec<1>(1.0));
  ASSERT_TRUE(prior);
  EXPECT_NEAR(prior->innovation(0), 0.8, 1e-12);
  EXPECT_NEAR(prior->state_covariance(0, 0), 0.01 * 1.25, 1e-12);
  EXPECT_EQ(ekf.state(), Eigen::Vector3d(0.2, 0.0, 0.0));
  const auto result = ekf.update(model, Vec<1>(1.0), 1e9);
  EXPECT_NEAR(result.nis, 0.8 * 0.8 / (0.0125 + 0.04), 1e-9);
  EXPECT_FALSE(ekf.prior_innovation(model, Vec<1>(std::nan(""))));
}

TEST(Ekf, RefusesASingularInnovationCovariance) {
  Ekf<3> ekf;
  ekf.reset(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  const Eigen::Matrix<double, 1, 3> h(1.0, 0.0, 0.0);
  const auto result = ekf.update(LinearModel<1, 3>(h, Mat<1, 1>(0.0)), Vec<1>(0.1), 1e9);
  EXPECT_EQ(result.outcome, FilterOutcome::kSingularInnovation);
}

TEST(Ekf, JosephFormKeepsCovarianceSymmetricPositiveDefinite) {
  Ekf<3> ekf;
  ekf.reset(Eigen::Vector3d::Zero(), 1e3 * Eigen::Matrix3d::Identity());
  const Eigen::Matrix<double, 1, 3> h(0.6, 0.8, 0.0);
  for (int i = 0; i < 1000; ++i) {
    ekf.update(LinearModel<1, 3>(h, Mat<1, 1>(1e-8)), Vec<1>(0.0));
  }
  const Eigen::Matrix3d p = ekf.covariance();
  EXPECT_EQ(p, p.transpose());  // exactly: consumers (ROS 2 tools) check symmetry
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(p);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
}

// P = F P F^T + Q rounds to a slightly asymmetric matrix; the filter must hand out an exactly
// symmetric one. (An in-place `p = 0.5 * (p + p.transpose())` does not: Eigen's transpose
// aliasing made it asymmetric by up to the off-diagonal difference.)
TEST(Ekf, PredictedAndUpdatedCovariancesAreExactlySymmetric) {
  Eigen::Matrix3d m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  EXPECT_EQ(symmetrized(m), symmetrized(m).transpose());
  EXPECT_EQ(symmetrized(m)(0, 2), 5.0);
  Ekf<3> ekf;
  Eigen::Matrix3d p0;
  p0 << 0.3, 0.1, 0.05, 0.1, 0.2, 0.02, 0.05, 0.02, 0.1;
  ekf.reset(Eigen::Vector3d::Zero(), p0);
  Eigen::Matrix3d f;
  f << 1.0, 0.01, 0.37, 0.0, 1.0, -0.29, 0.013, 0.0, 1.0;
  for (int i = 0; i < 100; ++i) {
    ekf.predict(LinearMotion<3, 1>(f, Eigen::Vector3d::Zero(), Mat<1, 1>(0.0), 1e-3 * Eigen::Matrix3d::Identity()),
                Vec<1>(0.0), 0.01);
    ASSERT_EQ(ekf.covariance(), ekf.covariance().transpose()) << i;
    ekf.update(LinearModel<1, 3>(Eigen::Matrix<double, 1, 3>(0.3, -0.7, 0.2), Mat<1, 1>(0.01)), Vec<1>(0.01));
    ASSERT_EQ(ekf.covariance(), ekf.covariance().transpose()) << i;
  }
}

}  // namespace
}  // namespace beaconloc
