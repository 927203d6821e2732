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

}  // namespace beaconloc
