#pragma once
// Plots as SVG, written without any dependency: the trajectory (truth, estimate, beacons, map)
// and the errors over time. Throws std::runtime_error when the file cannot be written.
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/occupancy_grid.hpp"
#include "evaluation.hpp"

namespace beaconloc {

void write_trajectory_svg(const std::string& path, const std::string& title, const TruthTrack& truth,
                          const std::vector<EstimateRow>& estimates, const BeaconMap& beacons,
                          const std::optional<OccupancyGrid>& map = std::nullopt);

void write_error_svg(const std::string& path, const std::string& title,
                     const std::vector<ErrorPoint>& errors);

// Empirical CDFs of several samples on one set of axes (seed 003 Fig. 11: the beacons' calibration
// error for several d_min), each a labelled step line; x_label names the quantity and its unit.
struct CdfSeries {
  std::string label;
  std::vector<double> values;
};
void write_cdf_svg(const std::string& path, const std::string& title, const std::string& x_label,
                   const std::vector<CdfSeries>& series);

}  // namespace beaconloc
