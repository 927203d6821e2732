#pragma once
// What the simulated laser reads: the room as built (its own grid, finer than the map's, with
// furniture the map lacks), people walking in it, and the scanner's own errors: a statistical
// and a systematic error (LaserModel, scenario.hpp) and a spot that widens with the range, whose
// reading where it straddles an edge is a mixed pixel (the scanner reports one distance for
// echoes that overlap). Seed 001 works in a "partially unknown" classroom (Sec. 4.1) with a SICK
// LMS-511; the figures of that scanner are in examples/scenarios/seed001_classroom_unknown.yaml.
#include <optional>
#include <vector>

#include "beaconloc/core/occupancy_grid.hpp"

namespace beaconloc::sim {

// A disc on the floor (a person at the scanner's height) at one instant.
struct Disc {
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();
  double radius_m = 0.2;
};

// A person (or anything else that moves and that no map has): a disc walking a polyline at a
// constant speed, there and back again, from its first point at t = 0.
class Walker {
 public:
  // Throws std::invalid_argument for fewer than two points, a speed or radius not > 0, or a
  // path of no length.
  Walker(std::vector<Eigen::Vector2d> path_m, double speed_mps, double radius_m);
  Disc at(double t_s) const;

 private:
  std::vector<Eigen::Vector2d> path_m_;
  std::vector<double> along_m_;  // distance along the path at each point, from 0
  double speed_mps_;
  double radius_m_;
};

// Where everyone is at t_s.
std::vector<Disc> discs_at(const std::vector<Walker>& people, double t_s);

// The scanner's spot and how it turns the surfaces under it into one reading.
struct LaserSpot {
  double diameter_at_window_m = 0.0;  // spot diameter at the front screen
  double divergence_rad = 0.0;        // its full-angle growth per metre of range; both 0: an ideal ray
  // Echoes from surfaces within this distance of the nearest merge into one pulse: the reading is
  // their mean (a mixed pixel, between the surfaces); echoes farther behind are not reported (the
  // first echo wins).
  double echo_merge_m = 0.0;
  bool ideal() const { return diameter_at_window_m <= 0.0 && divergence_rad <= 0.0; }
};

// The nearest surface along a ray: the world's occupied cells or a disc (a disc the ray starts
// inside is not seen: no one stands where the scanner is). nullopt: none within max_range_m.
std::optional<double> first_surface_m(const OccupancyGrid& world, const std::vector<Disc>& discs,
                                      const Eigen::Vector2d& from_m, double angle_rad, double max_range_m);

// A beam's distance before the scanner's range noise: an ideal spot reads the surface on its
// axis; a real one is a cone from the front screen, sampled by rays across it (each from its
// point of the screen, at its share of the divergence), and reads the mean of those whose
// surfaces lie within echo_merge_m of the nearest (LaserSpot).
std::optional<double> spot_reading_m(const OccupancyGrid& world, const std::vector<Disc>& discs,
                                     const LaserSpot& spot, const Eigen::Vector2d& from_m, double angle_rad,
                                     double max_range_m);

}  // namespace beaconloc::sim
