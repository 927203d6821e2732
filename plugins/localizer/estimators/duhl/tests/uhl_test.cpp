// UHL (seed 000, Section II-B): exact on noise-free distances for triangle, grid and collinear
// Tx layouts, all 12 orientations of the paper, robot inside and outside the Tx polygon.
// With sigma_d = 0.01 m (Sec. V), 12 orientations x 500 runs: within the paper's 0.02 m mean
// position error, and a mean heading error near the Cramer-Rao bound of the geometry. The paper's
// 1 degree is below that bound for these layouts (triangle inside: bound ~2.3 degrees mean), so it
// cannot have come from 0.01 m of static noise per distance.
#include "duhl/uhl.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <random>

#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/receiver_array.hpp"

namespace beaconloc::duhl {
namespace {

std::vector<TxDistances> measure(const Pose2& truth, const std::vector<Eigen::Vector3d>& txs,
                                 double sigma_m = 0.0, std::mt19937_64* rng = nullptr) {
  const auto rx = ReceiverArray::on_circle(0.19, 3);  // eq. 1
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<TxDistances> out;
  for (const auto& t : txs) {
    TxDistances d;
    d.tx_map_m = t;
    for (int l = 0; l < 3; ++l) {
      d.distances_m(l) =
          predict_range(truth, rx.receivers_base_m[l], 0.0, t).range_m + (rng ? sigma_m * noise(*rng) : 0.0);
    }
    out.push_back(d);
  }
  return out;
}

const std::vector<Eigen::Vector3d> kTriangle = {{0.0, 0.0, 2.011}, {2.0, 0.0, 2.011}, {1.0, 1.7, 2.011}};
const std::vector<Eigen::Vector3d> kGrid = {{0.0, 0.0, 2.011}, {1.5, 0.0, 2.011}, {3.0, 0.0, 2.011},
                                            {0.0, 1.5, 2.011}, {1.5, 1.5, 2.011}, {3.0, 1.5, 2.011}};
const std::vector<Eigen::Vector3d> kCollinear = {{0.0, 0.0, 2.011}, {1.5, 0.0, 2.011}, {3.0, 0.0, 2.011}};

struct Case {
  const char* name;
  std::vector<Eigen::Vector3d> txs;
  Eigen::Vector2d position;
  UhlMethod expected_method;
};

TEST(Uhl, RecoversNoiseFreePosesForEveryLayoutAndTheTwelveHeadings) {
  const std::vector<Case> cases = {
      {"triangle, inside", kTriangle, {1.0, 0.6}, UhlMethod::kIndirect},
      {"triangle, outside", kTriangle, {3.2, 2.1}, UhlMethod::kIndirect},
      {"grid, inside", kGrid, {0.8, 0.9}, UhlMethod::kIndirect},
      {"grid, outside", kGrid, {-1.0, 2.5}, UhlMethod::kIndirect},
      {"collinear, off the line", kCollinear, {1.2, 1.1}, UhlMethod::kIndirect},
      {"collinear, other side", kCollinear, {2.4, -0.9}, UhlMethod::kIndirect},
      {"collinear, near the line", kCollinear, {0.7, 0.1}, UhlMethod::kDirect},
      {"collinear, beyond the end", kCollinear, {4.5, 0.05}, UhlMethod::kDirect},
      {"two Txs", {kGrid[0], kGrid[4]}, {0.3, 1.0}, UhlMethod::kIndirect},
  };
  for (const auto& c : cases) {
    for (int k = 0; k < 12; ++k) {  // 0 to 330 degrees every 30, as in the paper's experiments
      const Pose2 truth(c.position.x(), c.position.y(), wrap_angle_rad(k * M_PI / 6.0));
      const UhlSolution s = solve_uhl(measure(truth, c.txs));
      ASSERT_TRUE(s.ok) << c.name << ": " << s.failure;
      EXPECT_LT((s.pose.head<2>() - truth.head<2>()).norm(), 1e-6) << c.name << ", " << 30 * k << " deg";
      EXPECT_LT(std::abs(wrap_angle_rad(s.pose.z() - truth.z())), 1e-6) << c.name << ", " << 30 * k << " deg";
      EXPECT_EQ(s.method, c.expected_method) << c.name;
    }
  }
}

TEST(Uhl, AnalyticJacobianMatchesNumericWhereTableOneTakesTheImr) {
  std::mt19937_64 rng(7);
  const std::vector<Case> cases = {
      {"triangle, inside", kTriangle, {1.0, 0.6}, UhlMethod::kIndirect},
      {"triangle, outside", kTriangle, {3.2, 2.1}, UhlMethod::kIndirect},
      {"grid, inside", kGrid, {0.8, 0.9}, UhlMethod::kIndirect},
      {"grid, outside", kGrid, {-1.0, 2.5}, UhlMethod::kIndirect},
  };
  for (const auto& c : cases) {
    for (int k = 0; k < 12; ++k) {
      // Noisy distances: the Jacobian is needed away from the exact geometry too.
      const auto txs = measure(Pose2(c.position.x(), c.position.y(), k * M_PI / 6.0), c.txs, 0.01, &rng);
      const UhlSolution s = solve_uhl(txs);
      ASSERT_TRUE(s.ok);
      const auto analytic = uhl_jacobian(txs, s);
      ASSERT_TRUE(analytic) << c.name;
      const UhlJacobian numeric = uhl_jacobian_numeric(txs);
      EXPECT_LT((*analytic - numeric).cwiseAbs().maxCoeff(), 1e-6 * (1.0 + numeric.cwiseAbs().maxCoeff()))
          << c.name << ", " << 30 * k << " deg\n"
          << *analytic << "\n"
          << numeric;
    }
  }
  // Collinear Txs: the other branches of Table I are left to numeric differentiation.
  const auto collinear = measure(Pose2(1.2, 1.1, 0.3), kCollinear);
  EXPECT_FALSE(uhl_jacobian(collinear, solve_uhl(collinear)));
}

TEST(Uhl, CentreRangeIsTheIsotropicArrayMean) {
  // Eq. 11: rho^2 = mean of d_l^2 - r_R^2 equals the squared range from the robot centre.
  const Pose2 truth(0.4, -0.7, 1.3);
  const auto d = measure(truth, {kGrid[5]});
  const double rho = uhl_centre_range(d[0], UhlOptions{});
  EXPECT_NEAR(rho, (kGrid[5] - Eigen::Vector3d(0.4, -0.7, 0.0)).norm(), 1e-12);
}

// Cramer-Rao bound of the heading from the 3N distances (sigma each), averaged over the 12 headings.
double heading_bound_deg(const std::vector<Eigen::Vector3d>& txs, const Eigen::Vector2d& position,
                         double sigma) {
  const auto rx = ReceiverArray::on_circle(0.19, 3);
  double sum = 0.0;
  for (int k = 0; k < 12; ++k) {
    const Pose2 pose(position.x(), position.y(), k * M_PI / 6.0);
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
    for (const auto& t : txs) {
      for (int l = 0; l < 3; ++l) {
        const Eigen::RowVector3d j = predict_range(pose, rx.receivers_base_m[l], 0.0, t).jacobian_pose;
        information += j.transpose() * j / (sigma * sigma);
      }
    }
    sum += std::sqrt(information.inverse()(2, 2)) * 180.0 / M_PI;
  }
  return sum / 12.0;
}

TEST(Uhl, StaticAccuracyWithThePapersNoiseNearTheCramerRaoBound) {
  std::mt19937_64 rng(2013);
  const double sigma = 0.01;
  for (const auto& [name, txs, position] :
       std::vector<std::tuple<const char*, std::vector<Eigen::Vector3d>, Eigen::Vector2d>>{
           {"triangle, inside", kTriangle, {1.0, 0.6}}, {"grid, inside", kGrid, {1.2, 0.7}}}) {
    double sum_position = 0.0, sum_heading = 0.0;
    int n = 0;
    for (int k = 0; k < 12; ++k) {
      const Pose2 truth(position.x(), position.y(), wrap_angle_rad(k * M_PI / 6.0));
      for (int run = 0; run < 500; ++run) {
        const UhlSolution s = solve_uhl(measure(truth, txs, sigma, &rng));
        ASSERT_TRUE(s.ok) << s.failure;
        sum_position += (s.pose.head<2>() - truth.head<2>()).norm();
        sum_heading += std::abs(wrap_angle_rad(s.pose.z() - truth.z())) * 180.0 / M_PI;
        ++n;
      }
    }
    // A Gaussian's mean absolute error is sqrt(2 / pi) = 0.80 of its standard deviation.
    const double bound_mean_deg = std::sqrt(2.0 / M_PI) * heading_bound_deg(txs, position, sigma);
    std::printf(
        "UHL, %s, sigma_d 0.01 m, 12 x 500 runs: mean position error %.4f m, mean heading error %.2f deg "
        "(Cramer-Rao bound %.2f deg; the paper: 1 deg)\n",
        name, sum_position / n, sum_heading / n, bound_mean_deg);
    EXPECT_LE(sum_position / n, 0.02) << name;                  // the paper's figure
    EXPECT_LE(sum_heading / n, 1.25 * bound_mean_deg) << name;  // within 25 % of the best possible
    EXPECT_GT(bound_mean_deg, 1.0) << name;                     // why the paper's 1 degree is out of reach
  }
}

TEST(Uhl, RefusesWhatItCannotSolve) {
  EXPECT_EQ(solve_uhl(measure({0, 0, 0}, {kGrid[0]})).failure, "too_few_txs");
  auto d = measure({0.5, 0.5, 0.0}, kTriangle);
  d[1].distances_m(2) = std::nan("");
  EXPECT_EQ(solve_uhl(d).failure, "invalid_distances");
  // Two Txs at the same place: A is zero.
  EXPECT_EQ(solve_uhl(measure({0.5, 0.5, 0.0}, {kGrid[0], kGrid[0]})).failure, "orientation_unobservable");
}

}  // namespace
}  // namespace beaconloc::duhl
