#include "beaconloc/core/filters/unscented.hpp"

#include <cmath>
#include <stdexcept>

namespace beaconloc {

UnscentedWeights::UnscentedWeights(Eigen::Index l, const UnscentedParameters& p)
    : dimension(l), lambda(p.alpha * p.alpha * (static_cast<double>(l) + p.kappa) - static_cast<double>(l)) {
  const double n = static_cast<double>(l) + lambda;
  if (l < 1 || !(n > 0.0)) throw std::invalid_argument("unscented transform: L + lambda must be positive");
  mean = Eigen::VectorXd::Constant(2 * l + 1, 1.0 / (2.0 * n));
  covariance = mean;
  mean(0) = lambda / n;                                             // eq. 14
  covariance(0) = lambda / n + (1.0 - p.alpha * p.alpha + p.beta);  // eq. 14
}

std::optional<Eigen::MatrixXd> sigma_points(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance,
                                            const UnscentedWeights& w) {
  const Eigen::Index l = mean.size();
  if (l != w.dimension || covariance.rows() != l || covariance.cols() != l) {
    throw std::invalid_argument("sigma_points: sizes differ");
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(covariance);
  if (llt.info() != Eigen::Success) return std::nullopt;
  const Eigen::MatrixXd spread = std::sqrt(static_cast<double>(l) + w.lambda) * llt.matrixL().toDenseMatrix();
  Eigen::MatrixXd points(l, 2 * l + 1);
  points.col(0) = mean;
  points.middleCols(1, l) = spread.colwise() + mean;
  points.middleCols(1 + l, l) = (-spread).colwise() + mean;
  return points;
}

Eigen::VectorXd weighted_mean(const Eigen::MatrixXd& points, const UnscentedWeights& w) {
  return points * w.mean;
}

Eigen::MatrixXd weighted_cross_covariance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                                          const UnscentedWeights& w) {
  return a * w.covariance.asDiagonal() * b.transpose();
}

Eigen::MatrixXd weighted_covariance(const Eigen::MatrixXd& a, const UnscentedWeights& w) {
  const Eigen::Index m = a.rows(), count = a.cols();
  if (count != w.covariance.size() || count < 2) throw std::invalid_argument("weighted_covariance: sizes differ");
  if (!(w.covariance.tail(count - 1).array() == w.covariance(1)).all()) {
    throw std::invalid_argument("weighted_covariance: the weights of i >= 1 differ (eq. 14 makes them one number)");
  }
  Eigen::MatrixXd lower = Eigen::MatrixXd::Zero(m, m);
  lower.selfadjointView<Eigen::Lower>().rankUpdate(a.rightCols(count - 1), w.covariance(1));
  lower.selfadjointView<Eigen::Lower>().rankUpdate(a.col(0), w.covariance(0));
  return lower.selfadjointView<Eigen::Lower>();
}

}  // namespace beaconloc
