#pragma once
// Occupancy grid files in the ROS map_server layout, so maps made by ROS tools (map_saver,
// slam_toolbox) load as they are: a YAML file (image, resolution, origin [x, y, yaw],
// occupied_thresh, free_thresh, negate) next to a binary (P5) or text (P2) PGM image whose top
// row is the map's largest y. A cell is occupied when its occupancy, (255 - p) / 255 (p / 255
// with negate: 1), exceeds occupied_thresh; unknown cells count as free.
#include <stdexcept>
#include <string>

#include "beaconloc/core/occupancy_grid.hpp"

namespace beaconloc {

struct MapFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws MapFileError naming the file and what is wrong with it.
OccupancyGrid load_occupancy_grid(const std::string& yaml_path);
// The same from memory: the YAML text and the bytes of the image it names (the name is checked,
// not opened); yaml_origin and image_origin name them in messages.
OccupancyGrid parse_occupancy_grid(const std::string& yaml_text, const std::string& image_bytes,
                                   const std::string& yaml_origin = "<map yaml>",
                                   const std::string& image_origin = "<map image>");
// Writes yaml_path and, beside it, the PGM it names (same stem, .pgm).
void write_occupancy_grid(const OccupancyGrid& grid, const std::string& yaml_path);

}  // namespace beaconloc
