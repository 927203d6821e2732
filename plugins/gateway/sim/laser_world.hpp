#pragma once
// What the simulated laser reads: the room as built (its own grid, finer than the map's, with
// furniture the map lacks), people walking in it, and the scanner's own errors. Seed 001 works
// in a "partially unknown" classroom (Sec. 4.1: tables, desktop computers, partitions; a map made
// by ICP with manual corrections) with a SICK LMS-511, whose operating instructions give the
// spot (13 mm at the front screen, widening 11 mrad at standard resolution) and the errors
// (statistical 6 mm, systematic +-25 mm at 1-10 m). Where the spot straddles an edge the reading
// is a mixed pixel: the scanner reports one distance for echoes that overlap.
#include <optional>
#include <random>
#include <vector>

#include "beaconloc/core/occupancy_grid.hpp"

namespace beaconloc::sim {

// A person (or anything else that moves and that no map has): a disc walking a polyline at a
// constant speed, there and back again, from its first point at t = 0.
struct Walker {
  std::vector<Eigen::Vector2d> path_m;  // at least two points
  double speed_mps = 1.0;
  double radius_m = 0.2;
  Eigen::Vector2d position_at(double t_s) const;
};

// The scanner's spot and how it turns the surfaces under it into one reading.
struct LaserSpot {
  double diameter_at_window_m = 0.0;  // spot diameter at the front screen
  double divergence_rad = 0.0;        // its growth per metre of range; both 0: an ideal ray
  // Echoes from surfaces within this distance of the nearest merge into one pulse: the reading is
  // their mean (a mixed pixel, between the surfaces); echoes farther behind are not reported (the
  // first echo wins).
  double echo_merge_m = 0.0;
  bool ideal() const { return diameter_at_window_m <= 0.0 && divergence_rad <= 0.0; }
};

// The nearest surface along a ray: the world's occupied cells or a walker at t_s (a walker the
// ray starts inside is not seen: it cannot stand where the scanner is). nullopt: none within
// max_range_m.
std::optional<double> first_surface_m(const OccupancyGrid& world, const std::vector<Walker>& people, double t_s,
                                      const Eigen::Vector2d& from_m, double angle_rad, double max_range_m);

// A beam's distance before the scanner's range noise: an ideal spot reads the surface on its
// axis; a real one casts sub-rays across its width at the range the axis meets, and reads the
// mean of those whose surfaces lie within echo_merge_m of the nearest (LaserSpot).
std::optional<double> spot_reading_m(const OccupancyGrid& world, const std::vector<Walker>& people, double t_s,
                                     const LaserSpot& spot, const Eigen::Vector2d& from_m, double angle_rad,
                                     double max_range_m);

}  // namespace beaconloc::sim
