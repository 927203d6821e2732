#pragma once
// The scaled unscented transform (seed 001 eq. 2, 12-14, 18-20): sigma points of a Gaussian,
// their weights, and the weighted moments of transformed points. Sizes are known only at run
// time (one noise entry per laser beam and beacon), hence dynamic Eigen types. The filter that
// uses it knows its models; this file knows none.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <optional>

namespace beaconloc {

struct UnscentedParameters {
  double alpha = 0.6;  // seed 001 eq. 23
  double beta = 2.0;
  double kappa = 0.0;
};

// Eq. 14: lambda = alpha^2 (L + kappa) - L; mean weights w_m and covariance weights w_c.
struct UnscentedWeights {
  UnscentedWeights(Eigen::Index dimension, const UnscentedParameters& p);
  Eigen::Index dimension;
  double lambda;
  Eigen::VectorXd mean;        // w_i^(m), i = 0..2L
  Eigen::VectorXd covariance;  // w_i^(c)
};

// Eq. 2: the columns [mu, mu + sqrt(L + lambda) S_j, mu - sqrt(L + lambda) S_j], S the Cholesky
// factor of the covariance. nullopt when the covariance is not positive definite.
std::optional<Eigen::MatrixXd> sigma_points(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance,
                                            const UnscentedWeights& weights);

// Eq. 12 / 18: the weighted mean of the columns.
Eigen::VectorXd weighted_mean(const Eigen::MatrixXd& points, const UnscentedWeights& weights);

// Eq. 20: sum_i w_i^(c) (a_i - a_mean)(b_i - b_mean)^T over columns already centred
// (the caller subtracts its mean, wrapping angles where it must).
Eigen::MatrixXd weighted_cross_covariance(const Eigen::MatrixXd& a_centred, const Eigen::MatrixXd& b_centred,
                                          const UnscentedWeights& weights);

// Eq. 13 / 19: the same with b = a, symmetric: as the weights of i >= 1 are all one number
// (eq. 14), w_1 A_r A_r^T + w_0 a_0 a_0^T, each a rank update of one triangle (half the products
// of the general form), mirrored.
Eigen::MatrixXd weighted_covariance(const Eigen::MatrixXd& a_centred, const UnscentedWeights& weights);

}  // namespace beaconloc
