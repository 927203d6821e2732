// The calibrated beacon's covariance from the pairs (calibration_covariance.hpp): the sums give
// exactly the mean of J_i P_i J_i^T formed pair by pair, and the lever arm does what it should.
#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include "scan/calibration_covariance.hpp"

namespace beaconloc::scan {
namespace {

Eigen::Matrix2d direct(const std::vector<std::pair<Eigen::Vector2d, Cov3>>& pairs, const Eigen::Vector2d& b) {
  Eigen::Matrix2d sum = Eigen::Matrix2d::Zero();
  for (const auto& [p, cov] : pairs) {
    Eigen::Matrix<double, 2, 3> j;
    j << 1.0, 0.0, -(b.y() - p.y()), 0.0, 1.0, b.x() - p.x();
    sum += j * cov * j.transpose();
  }
  return sum / static_cast<double>(pairs.size());
}

TEST(CalibrationCovariance, IsTheMeanOfEachPairsPropagatedCovariance) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  CalibrationCovariance c;
  std::vector<std::pair<Eigen::Vector2d, Cov3>> pairs;
  for (int i = 0; i < 40; ++i) {
    Eigen::Matrix3d a = Eigen::Matrix3d::NullaryExpr([&] { return 0.1 * u(rng); });
    const Cov3 cov = a * a.transpose() + 1e-4 * Cov3::Identity();
    const Eigen::Vector2d p(10.0 + u(rng), 2.0 + 0.1 * u(rng));
    pairs.push_back({p, cov});
    c.add(p, cov);
  }
  for (const Eigen::Vector2d& b : {Eigen::Vector2d(12.0, 2.3), Eigen::Vector2d(-3.0, 40.0)}) {
    EXPECT_TRUE(c.at(b).isApprox(direct(pairs, b), 1e-9)) << c.at(b) << "\n" << direct(pairs, b);
  }
}

TEST(CalibrationCovariance, AHeadingErrorMovesAFarBeaconMoreAndAcrossTheLine) {
  CalibrationCovariance c;
  EXPECT_TRUE(c.at({1.0, 1.0}).isZero());  // no pair: nothing known, nothing claimed
  Cov3 cov = Cov3::Zero();
  cov(0, 0) = cov(1, 1) = 1e-4;  // 1 cm
  cov(2, 2) = 1e-4;              // 0.01 rad
  c.add({0.0, 0.0}, cov);
  const Eigen::Matrix2d near = c.at({0.0, 0.0}), far = c.at({5.0, 0.0});
  EXPECT_NEAR(near(0, 0), 1e-4, 1e-12);
  EXPECT_NEAR(near(1, 1), 1e-4, 1e-12);
  EXPECT_NEAR(far(0, 0), 1e-4, 1e-12);               // along the line: the position's alone
  EXPECT_NEAR(far(1, 1), 1e-4 + 25.0 * 1e-4, 1e-12);  // across: 5 m x 0.01 rad more
  c.clear();
  EXPECT_EQ(c.pairs(), 0u);
}

}  // namespace
}  // namespace beaconloc::scan
