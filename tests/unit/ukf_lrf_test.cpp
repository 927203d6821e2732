// Seed 001's estimator pieces: the laser model against a hand-made grid, the association of
// Table 2, the map file, and the estimator's refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/occupancy_grid_io.hpp"
#include "ukf_lrf/beacon_association.hpp"
#include "ukf_lrf/laser_model.hpp"

namespace beaconloc::ukf_lrf {
namespace {

// A 4 m x 3 m room of 10 cm cells, walls on the border cells.
OccupancyGrid room() {
  OccupancyGrid grid({0.0, 0.0}, 0.1, 40, 30);
  grid.fill_border();
  return grid;
}

TEST(LaserModel, ExpectedRangesAreExactToTheCellFace) {
  const OccupancyGrid grid = room();  // inner faces at x = 0.1, 3.9 and y = 0.1, 2.9
  LaserBeams beams;
  for (double a : {-M_PI / 2, 0.0, M_PI / 2, M_PI}) beams.add_beam(a);
  beams.max_range_m = 80.0;
  double r[4];
  expected_laser_ranges(grid, Pose2(1.05, 1.25, 0.0), beams, r);
  EXPECT_NEAR(r[0], 1.15, 1e-9);  // down to y = 0.1
  EXPECT_NEAR(r[1], 2.85, 1e-9);  // ahead to x = 3.9
  EXPECT_NEAR(r[2], 1.65, 1e-9);  // up to y = 2.9
  EXPECT_NEAR(r[3], 0.95, 1e-9);  // behind to x = 0.1
  // The robot turned by 90 degrees and a scanner mounted 0.2 m ahead of its centre.
  beams.mount_base = Pose2(0.2, 0.0, 0.0);
  expected_laser_ranges(grid, Pose2(1.05, 1.25, M_PI / 2), beams, r);
  EXPECT_NEAR(r[1], 1.45, 1e-9);  // from y = 1.45 up to 2.9
  EXPECT_NEAR(r[0], 2.85, 1e-9);  // to the right: +x, to x = 3.9
  // Nothing within range reads the maximum range.
  OccupancyGrid empty({0.0, 0.0}, 0.1, 40, 30);
  beams.max_range_m = 5.0;
  expected_laser_ranges(empty, Pose2(1.05, 1.25, 0.0), beams, r);
  EXPECT_EQ(r[1], 5.0);
}

TEST(BeaconAssociation, PicksTheBeaconWhosePredictedRangeExplainsTheMeasurement) {
  const std::vector<PredictedBeaconRange> beacons = {
      {1, 3.0, 0.2}, {2, 6.0, 0.2}, {3, 9.0, 0.2}, {4, 12.0, 0.2}};
  EXPECT_EQ(most_likely_beacon(3.3, beacons), 1u);
  EXPECT_EQ(most_likely_beacon(5.6, beacons), 2u);
  EXPECT_EQ(most_likely_beacon(9.4, beacons), 3u);
  EXPECT_EQ(most_likely_beacon(40.0, beacons), 4u);  // far from all: still the likeliest, no underflow
  // Maximum likelihood, not nearest mean: a wide prediction can win at equal distance.
  EXPECT_EQ(most_likely_beacon(5.0, {{1, 4.0, 0.01}, {2, 6.0, 4.0}}), 2u);
  EXPECT_FALSE(most_likely_beacon(5.0, {}));
}

TEST(OccupancyGridFile, RoundTripsAndRefusesMalformedFiles) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("beaconloc_map_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  OccupancyGrid grid({-1.5, 2.0}, 0.05, 30, 20);
  grid.fill_border();
  grid.set_occupied(7, 3, true);
  write_occupancy_grid(grid, (dir / "map.yaml").string());
  const OccupancyGrid back = load_occupancy_grid((dir / "map.yaml").string());
  ASSERT_EQ(back.width(), 30);
  ASSERT_EQ(back.height(), 20);
  EXPECT_EQ(back.resolution_m(), 0.05);
  EXPECT_EQ(back.origin_m(), Eigen::Vector2d(-1.5, 2.0));
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 30; ++x) EXPECT_EQ(back.occupied(x, y), grid.occupied(x, y)) << x << ", " << y;
  }
  // A text PGM as ROS tools may write it; its top row is the map's largest y.
  std::ofstream(dir / "text.pgm") << "P2\n# comment\n3 2\n255\n0 254 254\n254 254 0\n";
  std::ofstream(dir / "text.yaml") << "image: text.pgm\nresolution: 1.0\norigin: [0.0, 0.0, 0.0]\n";
  const OccupancyGrid text = load_occupancy_grid((dir / "text.yaml").string());
  EXPECT_TRUE(text.occupied(0, 1));
  EXPECT_TRUE(text.occupied(2, 0));
  EXPECT_FALSE(text.occupied(1, 0));
  // Malformed: each refused with a message naming the file.
  std::ofstream(dir / "rotated.yaml") << "image: text.pgm\nresolution: 1.0\norigin: [0.0, 0.0, 0.5]\n";
  std::ofstream(dir / "no_image.yaml") << "resolution: 1.0\norigin: [0.0, 0.0, 0.0]\n";
  std::ofstream(dir / "short.pgm") << "P5\n10 10\n255\nabc";
  std::ofstream(dir / "short.yaml") << "image: short.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n";
  std::ofstream(dir / "bad_resolution.yaml") << "image: text.pgm\nresolution: -1\norigin: [0, 0, 0]\n";
  for (const char* name :
       {"rotated.yaml", "no_image.yaml", "short.yaml", "bad_resolution.yaml", "missing.yaml"}) {
    EXPECT_THROW(load_occupancy_grid((dir / name).string()), MapFileError) << name;
  }
  std::filesystem::remove_all(dir);
}

TEST(UkfLrfEstimator, IsRegisteredInItsThreeModesAndRefusesWhatItCannotUse) {
  EstimatorConfig config;
  config.receivers.receivers_base_m = {{0.0, 0.0}};
  // The laser modes need the map.
  EXPECT_THROW(EstimatorRegistry::instance().create("ukf_lrf", config), std::invalid_argument);
  auto beacons_only = EstimatorRegistry::instance().create("ukf_lrf_beacons_only", config);
  EXPECT_FALSE(beacons_only->uses_laser());
  config.occupancy_grid = std::make_shared<const OccupancyGrid>(room());
  auto fusion = EstimatorRegistry::instance().create("ukf_lrf", config);
  EXPECT_TRUE(fusion->uses_laser());
  EXPECT_EQ(EstimatorRegistry::instance().create("ukf_lrf_laser_only", config)->name(), "ukf_lrf_laser_only");

  // Placed by hand: without an initial pose, no estimate, and odometry refused with a reason.
  OdometrySample o;
  o.wheel_base_m = 0.4;
  EXPECT_EQ(fusion->predict(o).rejection, "no_initial_pose");
  EXPECT_FALSE(fusion->estimate());

  config.initial_pose = Pose2(1.0, 1.0, 0.0);
  auto placed = EstimatorRegistry::instance().create("ukf_lrf", config);
  LaserScanSample bad;
  EXPECT_EQ(placed->update_laser(bad).rejection, "malformed_scan");  // no beams
  RangeMeasurement nan_range;
  nan_range.range_m = std::nan("");
  EXPECT_EQ(placed->update(nan_range).rejection, "invalid_range");
  RangeMeasurement before_map;
  before_map.range_m = 3.0;
  EXPECT_EQ(placed->update(before_map).rejection, "no_beacon_map");
  EXPECT_TRUE(placed->predict(o).accepted);
  ASSERT_TRUE(placed->estimate());
  EXPECT_EQ(placed->estimate()->pose_map_base, Pose2(1.0, 1.0, 0.0));
}

}  // namespace
}  // namespace beaconloc::ukf_lrf
