// The scaled unscented transform of the core (seed 001 eq. 2, 12-14, 18-20): exact moments of a
// quadratic, and a UKF step built from it equal to the Kalman filter on a linear model.
#include "beaconloc/core/filters/unscented.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "beaconloc/core/models/velocity_motion.hpp"

namespace beaconloc {
namespace {

TEST(Unscented, WeightsFollowEquationFourteen) {
  const UnscentedWeights w(28, {0.6, 2.0, 0.0});  // the paper's L and eq. 23
  EXPECT_NEAR(w.lambda, 0.36 * 28 - 28, 1e-12);
  EXPECT_NEAR(w.mean.sum(), 1.0, 1e-12);
  EXPECT_NEAR(w.covariance(0), w.mean(0) + 1.0 - 0.36 + 2.0, 1e-12);
  EXPECT_EQ(w.mean.size(), 57);
  EXPECT_THROW(UnscentedWeights(3, {0.001, 2.0, -3.0}), std::invalid_argument);  // L + lambda <= 0
}

// y = x^2 with x ~ N(mu, s^2): E[y] = mu^2 + s^2, Var[y] = 4 mu^2 s^2 + 2 s^4. With
// alpha = 1, kappa = 2 (L + lambda = 3, the Gaussian's kurtosis) and beta = 0, the transform
// reproduces both exactly.
TEST(Unscented, ReproducesTheMomentsOfASquaredGaussian) {
  const double mu = 1.3, s = 0.4;
  const UnscentedWeights w(1, {1.0, 0.0, 2.0});
  const auto chi = sigma_points(Eigen::VectorXd::Constant(1, mu), Eigen::MatrixXd::Constant(1, 1, s * s), w);
  ASSERT_TRUE(chi);
  const Eigen::MatrixXd y = chi->array().square().matrix();
  const Eigen::VectorXd mean = weighted_mean(y, w);
  const Eigen::MatrixXd centred = y.colwise() - mean;
  EXPECT_NEAR(mean(0), mu * mu + s * s, 1e-12);
  EXPECT_NEAR(weighted_cross_covariance(centred, centred, w)(0, 0), 4 * mu * mu * s * s + 2 * s * s * s * s,
              1e-12);
}

// Eq. 13 / 19 by rank updates of one triangle: the general product's sum to rounding, exactly
// symmetric; with the paper's alpha (eq. 23, w_0^(c) > 0 at L = 28) and a small one (w_0^(c) < 0).
TEST(Unscented, TheSymmetricCovarianceIsTheCrossCovarianceOfAColumnSetWithItself) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(23, 57);
  for (const double alpha : {0.6, 0.1}) {
    const UnscentedWeights w(28, {alpha, 2.0, 0.0});
    EXPECT_EQ(w.covariance(0) < 0.0, alpha == 0.1);
    const Eigen::MatrixXd general = weighted_cross_covariance(a, a, w);
    const Eigen::MatrixXd symmetric = weighted_covariance(a, w);
    EXPECT_LT((symmetric - general).cwiseAbs().maxCoeff(), 1e-12 * general.cwiseAbs().maxCoeff()) << alpha;
    EXPECT_EQ(symmetric, symmetric.transpose()) << alpha;
  }
  const UnscentedWeights w(28, {0.6, 2.0, 0.0});
  // Weights that eq. 14 would not give (i >= 1 unequal), or another count of columns: refused.
  UnscentedWeights altered = w;
  altered.covariance(5) *= 2.0;
  EXPECT_THROW(weighted_covariance(a, altered), std::invalid_argument);
  EXPECT_THROW(weighted_covariance(a.leftCols(56), w), std::invalid_argument);
}

TEST(Unscented, RefusesACovarianceThatIsNotPositiveDefinite) {
  const UnscentedWeights w(2, {});
  Eigen::MatrixXd p(2, 2);
  p << 1.0, 2.0, 2.0, 1.0;
  EXPECT_FALSE(sigma_points(Eigen::VectorXd::Zero(2), p, w));
}

// x' = F x + G n_u, z = H x' + n_z, the noises in the augmented state as in seed 001 eq. 1-8.
// One UKF step (eq. 2, 9, 12-13, 16, 18-22) against the Kalman filter's predict and update.
TEST(Unscented, UkfStepOnALinearModelIsTheKalmanFilter) {
  Eigen::Matrix3d f;
  f << 1.0, 0.0, 0.1, 0.2, 1.0, 0.0, 0.0, -0.1, 0.9;
  Eigen::Matrix<double, 3, 2> g;
  g << 0.1, 0.0, 0.0, 0.1, 0.05, 0.02;
  Eigen::Matrix<double, 2, 3> h;
  h << 1.0, 0.5, 0.0, 0.0, 1.0, -1.0;
  const Eigen::Vector3d x0(0.3, -1.2, 0.7);
  Eigen::Matrix3d p0;
  p0 << 0.5, 0.1, 0.0, 0.1, 0.3, 0.05, 0.0, 0.05, 0.2;
  const Eigen::Matrix2d m = Eigen::Vector2d(0.04, 0.09).asDiagonal();  // motion noise
  const Eigen::Matrix2d r = Eigen::Vector2d(0.01, 0.16).asDiagonal();  // measurement noise
  const Eigen::Vector2d z(0.9, -2.1);

  // Kalman filter.
  const Eigen::Vector3d x_kf_prior = f * x0;
  const Eigen::Matrix3d p_kf_prior = f * p0 * f.transpose() + g * m * g.transpose();
  const Eigen::Matrix2d s_kf = h * p_kf_prior * h.transpose() + r;
  const Eigen::Matrix<double, 3, 2> k_kf = p_kf_prior * h.transpose() * s_kf.inverse();
  const Eigen::Vector3d x_kf = x_kf_prior + k_kf * (z - h * x_kf_prior);
  const Eigen::Matrix3d p_kf = p_kf_prior - k_kf * s_kf * k_kf.transpose();

  // UKF on the augmented state [x, n_u, n_z] (L = 7), the paper's alpha, beta, kappa.
  Eigen::VectorXd mean_a = Eigen::VectorXd::Zero(7);
  mean_a.head<3>() = x0;
  Eigen::MatrixXd cov_a = Eigen::MatrixXd::Zero(7, 7);
  cov_a.topLeftCorner<3, 3>() = p0;
  cov_a.block<2, 2>(3, 3) = m;
  cov_a.block<2, 2>(5, 5) = r;
  const UnscentedWeights w(7, {0.6, 2.0, 0.0});
  const auto chi = sigma_points(mean_a, cov_a, w);
  ASSERT_TRUE(chi);
  const Eigen::MatrixXd x_sigma = f * chi->topRows(3) + g * chi->middleRows(3, 2);
  const Eigen::VectorXd x_prior = weighted_mean(x_sigma, w);
  const Eigen::MatrixXd x_centred = x_sigma.colwise() - x_prior;
  const Eigen::MatrixXd p_prior = weighted_cross_covariance(x_centred, x_centred, w);
  const Eigen::MatrixXd z_sigma = h * x_sigma + chi->bottomRows(2);
  const Eigen::VectorXd z_mean = weighted_mean(z_sigma, w);
  const Eigen::MatrixXd z_centred = z_sigma.colwise() - z_mean;
  const Eigen::MatrixXd s = weighted_cross_covariance(z_centred, z_centred, w);
  const Eigen::MatrixXd k = weighted_cross_covariance(x_centred, z_centred, w) * s.inverse();
  const Eigen::VectorXd x = x_prior + k * (z - z_mean);
  const Eigen::MatrixXd p = p_prior - k * s * k.transpose();

  EXPECT_LT((x - x_kf).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((p - p_kf).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(VelocityMotion, ArcAndTheStraightLineLimitAgree) {
  const Pose2 start(1.0, 2.0, 0.4);
  const Pose2 straight = predict_velocity_motion(start, 0.5, 0.0, 2.0);
  EXPECT_NEAR(straight.x(), 1.0 + std::cos(0.4), 1e-12);
  EXPECT_NEAR(straight.y(), 2.0 + std::sin(0.4), 1e-12);
  // A very slow turn is continuous with the straight line (eq. 10-11's omega -> 0 limit).
  const Pose2 slow = predict_velocity_motion(start, 0.5, 1e-7, 2.0);
  EXPECT_LT((slow - straight).head<2>().norm(), 1e-6);
  // A quarter circle of radius 1: v = 1, omega = 1, t = pi / 2.
  const Pose2 quarter = predict_velocity_motion(Pose2(0.0, 0.0, 0.0), 1.0, 1.0, M_PI / 2);
  EXPECT_NEAR(quarter.x(), 1.0, 1e-12);
  EXPECT_NEAR(quarter.y(), 1.0, 1e-12);
  EXPECT_NEAR(quarter.z(), M_PI / 2, 1e-12);
  // Eq. 6.
  EXPECT_EQ(velocity_noise_variance(0.5, 0.2, {0.1, 0.2, 0.3, 0.4}),
            Eigen::Vector2d(0.1 * 0.25 + 0.2 * 0.04, 0.3 * 0.25 + 0.4 * 0.04));
}

}  // namespace
}  // namespace beaconloc
