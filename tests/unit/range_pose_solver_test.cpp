// Global pose from ranges alone: exact on noise-free ranges from any start, refuses what it
// cannot solve.
#include "beaconloc/core/solvers/range_pose_solver.hpp"

#include <gtest/gtest.h>

#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/receiver_array.hpp"

namespace beaconloc {
namespace {

std::vector<RangeObservation> observe(const Pose2& truth, const std::vector<Eigen::Vector3d>& beacons,
                                      const ReceiverArray& rx) {
  std::vector<RangeObservation> obs;
  for (const auto& b : beacons) {
    for (const auto& r : rx.receivers_base_m) {
      RangeObservation o;
      o.receiver_solve_frame_m = r;
      o.beacon_map_m = b;
      o.range_m = predict_range(truth, r, 0.0, b).range_m;
      o.variance_m2 = 1e-4;
      obs.push_back(o);
    }
  }
  return obs;
}

const std::vector<Eigen::Vector3d> kTriangle = {{0.0, 0.0, 2.011}, {3.0, 0.0, 2.011}, {1.5, 2.6, 2.011}};

TEST(RangePoseSolver, RecoversNoiseFreePoseInsideAndOutsideForTwelveHeadings) {
  const auto rx = ReceiverArray::on_circle(0.19, 3);
  for (const Eigen::Vector2d& xy : {Eigen::Vector2d(1.5, 0.9), Eigen::Vector2d(4.0, -1.0)}) {
    for (int k = 0; k < 12; ++k) {
      const Pose2 truth(xy.x(), xy.y(), wrap_angle_rad(k * M_PI / 6));
      const auto sol = solve_pose_from_ranges(observe(truth, kTriangle, rx));
      ASSERT_TRUE(sol.ok) << sol.failure;
      EXPECT_NEAR((sol.pose.head<2>() - truth.head<2>()).norm(), 0.0, 1e-6);
      EXPECT_NEAR(wrap_angle_rad(sol.pose.z() - truth.z()), 0.0, 1e-6);
    }
  }
}

TEST(RangePoseSolver, ReceiversMovedByOdometryAreHonoured) {
  // Each range seen from a different pose of the robot, expressed in the frame solved for.
  const auto rx = ReceiverArray::on_circle(0.19, 3);
  const Pose2 now(1.0, 0.5, 0.4);
  std::vector<RangeObservation> obs;
  int i = 0;
  for (const auto& b : kTriangle) {
    const Pose2 then_in_now(-0.1 * (3 - i), 0.02 * i, -0.05 * i);  // the robot drove since
    const Pose2 then = compose(now, then_in_now);
    for (const auto& r : rx.receivers_base_m) {
      RangeObservation o;
      o.receiver_solve_frame_m = transform_point(then_in_now, r);
      o.beacon_map_m = b;
      o.range_m = predict_range(then, r, 0.0, b).range_m;
      obs.push_back(o);
    }
    ++i;
  }
  const auto sol = solve_pose_from_ranges(obs);
  ASSERT_TRUE(sol.ok) << sol.failure;
  EXPECT_NEAR((sol.pose - now).norm(), 0.0, 1e-6);
}

TEST(RangePoseSolver, RefusesTooFewRangesAndInconsistentOnes) {
  const auto rx = ReceiverArray::on_circle(0.19, 3);
  auto obs = observe({1.0, 1.0, 0.0}, {kTriangle[0]}, rx);
  EXPECT_EQ(solve_pose_from_ranges(obs).failure, "too_few_ranges");
  obs = observe({1.0, 1.0, 0.0}, kTriangle, rx);
  obs[4].range_m += 0.5;  // 50 sigma off
  EXPECT_EQ(solve_pose_from_ranges(obs).failure, "residual_too_large");
  obs[4].range_m = std::nan("");
  EXPECT_EQ(solve_pose_from_ranges(obs).failure, "invalid_observation");
}

// The fix's mirror image across the beacons' principal axis: as good a fit when the beacons are
// on one line and the receiver's path is symmetric about it (one receiver driving straight),
// far worse when identified receivers on a circle break the symmetry or the beacons spread.
TEST(RangePoseSolver, ReportsHowMuchWorseTheMirrorImageFits) {
  const std::vector<Eigen::Vector3d> row = {{0.0, 0.0, 2.5}, {2.0, 0.0, 2.5}, {4.0, 0.0, 2.5}};
  const Pose2 now(1.5, 1.2, 0.3);
  std::vector<RangeObservation> straight;
  for (int k = 0; k < 4; ++k) {
    const Pose2 then_in_now(-0.3 * k, 0.0, 0.0);  // one receiver at the centre, driving straight
    for (const auto& b : row) {
      RangeObservation o;
      o.receiver_solve_frame_m = then_in_now.head<2>();
      o.beacon_map_m = b;
      o.range_m = predict_range(compose(now, then_in_now), Eigen::Vector2d::Zero(), 0.0, b).range_m;
      straight.push_back(o);
    }
  }
  const auto one = solve_pose_from_ranges(straight);
  ASSERT_TRUE(one.ok) << one.failure;
  EXPECT_LT(one.mirror_cost_margin, 1e-6);  // the ranges cannot say which side of the row

  const auto ring = solve_pose_from_ranges(observe(now, row, ReceiverArray::on_circle(0.19, 3)));
  ASSERT_TRUE(ring.ok) << ring.failure;
  EXPECT_NEAR((ring.pose - now).norm(), 0.0, 1e-6);
  EXPECT_GT(ring.mirror_cost_margin, 100.0);  // receivers 1 and 2 would swap sides

  const auto spread = solve_pose_from_ranges(observe(now, kTriangle, ReceiverArray::on_circle(0.19, 3)));
  ASSERT_TRUE(spread.ok) << spread.failure;
  EXPECT_GT(spread.mirror_cost_margin, 1000.0);
}

}  // namespace
}  // namespace beaconloc
