// Motion and measurement models: analytic Jacobians against central differences, values against
// direct geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc {
namespace {

constexpr double kStep = 1e-6;

TEST(DiffDriveMotion, PoseJacobianMatchesNumeric) {
  for (double yaw : {-3.0, -1.2, 0.0, 0.7, 2.9}) {
    for (auto [vr, vl] : {std::pair{0.34, 0.34}, {0.5, 0.1}, {-0.2, 0.3}, {1.02, 0.9}}) {
      const Pose2 x(1.3, -0.4, yaw);
      const auto p = predict_diff_drive(x, vr, vl, 0.33, 0.01);
      for (int j = 0; j < 3; ++j) {
        Pose2 hi = x, lo = x;
        hi[j] += kStep;
        lo[j] -= kStep;
        Eigen::Vector3d d =
            predict_diff_drive(hi, vr, vl, 0.33, 0.01).pose - predict_diff_drive(lo, vr, vl, 0.33, 0.01).pose;
        d.z() = wrap_angle_rad(d.z());
        EXPECT_TRUE(p.jacobian_pose.col(j).isApprox(d / (2 * kStep), 1e-6))
            << "column " << j << " yaw " << yaw << "\n"
            << p.jacobian_pose << "\n"
            << d.transpose() / (2 * kStep);
      }
    }
  }
}

TEST(DiffDriveMotion, WheelJacobianMatchesNumericWithErratumCorrection) {
  // ERRATA (seed 000 eq. 16): d[Delta D, Delta phi]/d[v_R, v_L] = [[dT/2, dT/2], [dT/B, -dT/B]].
  for (double yaw : {-2.0, 0.0, 1.0}) {
    for (auto [vr, vl] : {std::pair{0.34, 0.34}, {0.5, 0.1}, {0.0, 0.0}, {-0.3, 0.2}}) {
      const Pose2 x(0.0, 2.0, yaw);
      const double b = 0.33, dt = 0.01;
      const auto p = predict_diff_drive(x, vr, vl, b, dt);
      const double u[2] = {vr, vl};
      for (int j = 0; j < 2; ++j) {
        double hi[2] = {u[0], u[1]}, lo[2] = {u[0], u[1]};
        hi[j] += kStep;
        lo[j] -= kStep;
        Eigen::Vector3d d =
            predict_diff_drive(x, hi[0], hi[1], b, dt).pose - predict_diff_drive(x, lo[0], lo[1], b, dt).pose;
        d.z() = wrap_angle_rad(d.z());
        EXPECT_TRUE(p.jacobian_wheels.col(j).isApprox(d / (2 * kStep), 1e-6)) << "column " << j << "\n"
                                                                              << p.jacobian_wheels << "\n"
                                                                              << d.transpose() / (2 * kStep);
      }
    }
  }
}

TEST(DiffDriveMotion, StraightAndTurningIncrements) {
  // Straight at 0.34 m/s for 10 ms along yaw 90 deg: +3.4 mm in y.
  auto p = predict_diff_drive({1.0, 1.0, M_PI / 2}, 0.34, 0.34, 0.33, 0.01);
  EXPECT_NEAR(p.pose.x(), 1.0, 1e-12);
  EXPECT_NEAR(p.pose.y(), 1.0034, 1e-12);
  EXPECT_NEAR(p.pose.z(), M_PI / 2, 1e-12);
  // Spin in place: heading change dT (v_R - v_L) / B, no translation.
  p = predict_diff_drive({0.0, 0.0, 0.0}, 0.165, -0.165, 0.33, 0.01);
  EXPECT_NEAR(p.pose.head<2>().norm(), 0.0, 1e-12);
  EXPECT_NEAR(p.pose.z(), 0.01, 1e-12);
}

TEST(RangeModel, ValueIsTheThreeDimensionalDistance) {
  const Eigen::Vector3d beacon(2.0, 1.0, 2.011);
  const Pose2 x(0.5, -0.25, 0.8);
  const Eigen::Vector2d rx(0.19 * std::cos(2 * M_PI / 3), 0.19 * std::sin(2 * M_PI / 3));
  const Eigen::Vector2d rx_map = transform_point(x, rx);
  const double expected =
      std::sqrt(std::pow(rx_map.x() - 2.0, 2) + std::pow(rx_map.y() - 1.0, 2) + std::pow(2.011, 2));
  EXPECT_NEAR(predict_range(x, rx, 0.0, beacon).range_m, expected, 1e-12);
}

TEST(RangeModel, JacobianMatchesNumeric) {
  const Eigen::Vector3d beacon(1.5, -0.3, 2.011);
  for (double yaw : {-2.5, -0.3, 0.0, 1.1, 3.0}) {
    for (const Eigen::Vector2d& rx :
         {Eigen::Vector2d(0.19, 0.0), Eigen::Vector2d(-0.095, 0.1645), Eigen::Vector2d(0.0, 0.0)}) {
      for (double rz : {0.0, 0.3}) {
        const Pose2 x(0.2, 1.4, yaw);
        const auto p = predict_range(x, rx, rz, beacon);
        for (int j = 0; j < 3; ++j) {
          Pose2 hi = x, lo = x;
          hi[j] += kStep;
          lo[j] -= kStep;
          const double numeric =
              (predict_range(hi, rx, rz, beacon).range_m - predict_range(lo, rx, rz, beacon).range_m) /
              (2 * kStep);
          EXPECT_NEAR(p.jacobian_pose(j), numeric, 1e-8) << "j " << j << " yaw " << yaw;
        }
      }
    }
  }
}

}  // namespace
}  // namespace beaconloc

namespace beaconloc {
namespace {

TEST(WrapAngle, KeepsAnAngleInsideBitForBitAndWrapsOthersIntoMinusPiExcludedToPi) {
  for (const double a : {0.0, -0.0, 1e-300, 3.0, -3.0, M_PI, std::nextafter(-M_PI, 0.0), 2.5}) {
    EXPECT_EQ(wrap_angle_rad(a), a) << a;
  }
  EXPECT_EQ(wrap_angle_rad(-M_PI), M_PI);  // the interval's one end
  EXPECT_EQ(wrap_angle_rad(3.0 * M_PI), M_PI);
  // Against the trigonometric definition, on a sweep far outside and across the ends.
  for (double a = -1000.0; a < 1000.0; a += 0.377) {
    const double w = wrap_angle_rad(a);
    EXPECT_GT(w, -M_PI) << a;
    EXPECT_LE(w, M_PI) << a;
    EXPECT_NEAR(std::remainder(w - std::atan2(std::sin(a), std::cos(a)), 2.0 * M_PI), 0.0, 1e-12) << a;
  }
  EXPECT_TRUE(std::isnan(wrap_angle_rad(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_TRUE(std::isnan(wrap_angle_rad(std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(wrap_angle_rad(-std::numeric_limits<double>::infinity())));
}

}  // namespace
}  // namespace beaconloc
