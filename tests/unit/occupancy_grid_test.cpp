// Ray casting on the occupancy grid against hand-made grids: exact to the cell boundary.
#include "beaconloc/core/occupancy_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace beaconloc {
namespace {

TEST(OccupancyGrid, RayStopsAtTheFaceOfTheFirstOccupiedCell) {
  OccupancyGrid grid({0.0, 0.0}, 0.1, 50, 30);  // 5 m x 3 m
  grid.set_occupied(40, 10, true);              // cell [4.0, 4.1) x [1.0, 1.1)
  // From (1.05, 1.05) along +x: hits the cell's left face at x = 4.0.
  EXPECT_NEAR(*grid.cast_ray({1.05, 1.05}, 0.0, 10.0), 2.95, 1e-9);
  // Along -x nothing: outside cells are free.
  EXPECT_FALSE(grid.cast_ray({1.05, 1.05}, M_PI, 10.0));
  // Too short a range.
  EXPECT_FALSE(grid.cast_ray({1.05, 1.05}, 0.0, 2.9));
}

TEST(OccupancyGrid, DiagonalRaysAndBorders) {
  OccupancyGrid grid({-1.0, -1.0}, 0.1, 20, 20);  // [-1, 1] x [-1, 1]
  grid.fill_border();                             // cells at index 0 and 19
  // From the centre at 45 degrees: reaches the corner cell, whose face is at 0.9.
  EXPECT_NEAR(*grid.cast_ray({0.0, 0.0}, M_PI / 4, 10.0), 0.9 * std::sqrt(2.0), 1e-9);
  // Straight up from (0.05, 0.05): face at y = 0.9.
  EXPECT_NEAR(*grid.cast_ray({0.05, 0.05}, M_PI / 2, 10.0), 0.85, 1e-9);
  // Every direction hits the border within the box.
  for (int k = 0; k < 360; ++k) {
    const double a = k * M_PI / 180.0;
    const auto r = grid.cast_ray({0.03, -0.02}, a, 10.0);
    ASSERT_TRUE(r) << k;
    const Eigen::Vector2d hit = Eigen::Vector2d(0.03, -0.02) + *r * Eigen::Vector2d(std::cos(a), std::sin(a));
    EXPECT_GE(hit.cwiseAbs().maxCoeff(), 0.9 - 1e-9) << k;
    EXPECT_LE(hit.cwiseAbs().maxCoeff(), 0.9 + 1e-9) << k;
  }
}

TEST(OccupancyGrid, StartInsideAnObstacleReadsZeroAndRectanglesFillByCellCentre) {
  OccupancyGrid grid({0.0, 0.0}, 0.1, 30, 30);
  grid.fill_rectangle({1.0, 1.0}, {1.5, 1.2});
  EXPECT_TRUE(grid.occupied_at({1.05, 1.05}));
  EXPECT_TRUE(grid.occupied_at({1.45, 1.15}));
  EXPECT_FALSE(grid.occupied_at({1.55, 1.15}));
  EXPECT_FALSE(grid.occupied_at({0.95, 1.05}));
  EXPECT_EQ(*grid.cast_ray({1.2, 1.1}, 0.3, 5.0), 0.0);
  EXPECT_NEAR(*grid.cast_ray({0.25, 1.15}, 0.0, 5.0), 0.75, 1e-9);
}

}  // namespace
}  // namespace beaconloc
