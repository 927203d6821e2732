#pragma once
// The laser measurement model of seed 001 (h for the LRF in eq. 16): the range each beam would
// measure from a robot pose, by ray casting on the occupancy grid (10 cm cells, Sec. 4.1).
#include <cmath>
#include <vector>

#include "beaconloc/core/occupancy_grid.hpp"
#include "beaconloc/core/pose2.hpp"

namespace beaconloc::ukf_lrf {

struct LaserBeams {
  Pose2 mount_base = Pose2::Zero();  // the scanner's pose on the robot
  double max_range_m = 80.0;         // what a beam that hits nothing reads
  // Each beam's unit direction in the scanner frame.
  std::vector<Eigen::Vector2d> directions;
  void add_beam(double angle_rad) { directions.emplace_back(std::cos(angle_rad), std::sin(angle_rad)); }
  std::size_t size() const { return directions.size(); }
};

// Expected range of every beam from the robot pose pose_map_base; a beam that meets no
// occupied cell within max_range_m reads max_range_m.
void expected_laser_ranges(const OccupancyGrid& grid, const Pose2& pose_map_base, const LaserBeams& beams,
                           double* ranges_out);

}  // namespace beaconloc::ukf_lrf
