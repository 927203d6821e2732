// Ray casting on the occupancy grid against hand-made grids: exact to the cell boundary.
#include "beaconloc/core/occupancy_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

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

// A grid is what a map can be: the constructor refuses the numbers that made ray casting spin.
TEST(OccupancyGrid, TheConstructorRefusesWhatNoMapCanBe) {
  const double nan = std::nan("");
  EXPECT_THROW(OccupancyGrid({0.0, 0.0}, 1e-300, 10, 10), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid({0.0, 0.0}, 11.0, 10, 10), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid({1e300, 0.0}, 0.1, 10, 10), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid({nan, 0.0}, 0.1, 10, 10), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid({0.0, 0.0}, 0.1, 0, 10), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid({0.0, 0.0}, 0.1, 20001, 1), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid({0.0, 0.0}, 0.1, 20000, 20000), std::invalid_argument);  // 4e8 cells
  EXPECT_NO_THROW(OccupancyGrid({-1e6, 1e6}, 1e-3, 20000, 1));
}

// Ray casting is bounded by the grid: a ray visits at most width + height cells, wherever it
// starts and however long its range. Before, a start far outside walked cell by cell from there
// (and converted an out-of-range double to int): 1e-300 m cells or a 1e300 m origin spun forever.
TEST(OccupancyGrid, RayCastingIsBoundedWhateverTheStartAndTheRange) {
  OccupancyGrid grid({0.0, 0.0}, 1e-3, 2000, 1000);  // 2 m x 1 m of 1 mm cells
  grid.fill_border();
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  // From 1e12 m away (1e15 cells), with an infinite range: it enters the grid and hits the
  // border's outer face, exactly.
  const auto far = grid.cast_ray({-1e12, 0.5}, 0.0, inf);
  ASSERT_TRUE(far);
  EXPECT_NEAR(*far, 1e12, 1e-3);
  // Inside, with an infinite range: the far border's inner face.
  EXPECT_NEAR(*grid.cast_ray({1.0005, 0.5005}, 0.0, inf), 0.9985, 1e-9);
  // Away from the grid, beside it, from absurd or non-finite places, along a zero direction.
  EXPECT_FALSE(grid.cast_ray({-1e12, 0.5}, M_PI, inf));
  EXPECT_FALSE(grid.cast_ray({-1.0, 5.0}, 0.0, inf));
  EXPECT_FALSE(grid.cast_ray({1e300, -1e300}, 2.0, inf));
  EXPECT_FALSE(grid.cast_ray({nan, 0.5}, 0.0, 10.0));
  EXPECT_FALSE(grid.cast_ray({inf, 0.5}, M_PI, 10.0));
  EXPECT_FALSE(grid.cast_ray({1.0, 0.5}, nan, 10.0));
  EXPECT_FALSE(grid.cast_ray({1.0, 0.5}, 0.0, nan));
  EXPECT_FALSE(grid.cast_ray_along({1.0, 0.5}, {0.0, 0.0}, inf));
  EXPECT_EQ(*grid.cast_ray_along({0.0005, 0.5}, {0.0, 0.0}, inf), 0.0);  // in the border
  // Every direction from a far start: each answer is finite, or none.
  for (int k = 0; k < 64; ++k) {
    const auto r = grid.cast_ray({-1e9, 3e8}, k * M_PI / 32, inf);
    if (r) {
      EXPECT_TRUE(std::isfinite(*r)) << k;
    }
  }
  // Points far outside are outside, with no conversion of a huge double to int.
  EXPECT_FALSE(grid.occupied_at({1e300, 0.5}));
  EXPECT_FALSE(grid.occupied_at({nan, nan}));
  EXPECT_EQ(grid.cell_of({-1e300, 1e300}), Eigen::Vector2i(-1, 1000));
}

}  // namespace
}  // namespace beaconloc
