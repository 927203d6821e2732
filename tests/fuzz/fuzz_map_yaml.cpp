// Fuzz target: the occupancy grid loader (plugins/sdk/src/occupancy_grid_io.cpp), the ROS
// map_server YAML and the PGM image it names, from memory (parse_occupancy_grid, which the
// file loader calls). Input: the YAML text, a line "%%", then the image's bytes. It must load a
// grid or throw MapFileError; any other exception, a crash, undefined behaviour, a hang or an
// allocation out of proportion to the input is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "beaconloc/core/occupancy_grid_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n%%\n";
  const std::size_t at = input.find(separator);
  const std::string yaml = input.substr(0, at);
  const std::string image = at == std::string::npos ? std::string() : input.substr(at + separator.size());
  try {
    const beaconloc::OccupancyGrid grid =
        beaconloc::parse_occupancy_grid(yaml, image, "fuzz.yaml", "fuzz.pgm");
    // Every cell came from a pixel: the image held at least that many bytes.
    if (grid.width() <= 0 || grid.height() <= 0 ||
        static_cast<std::size_t>(grid.width()) * static_cast<std::size_t>(grid.height()) > image.size()) {
      __builtin_trap();
    }
  } catch (const beaconloc::MapFileError&) {
  }
  return 0;
}
