// Fuzz target: the occupancy grid loader (plugins/sdk/src/occupancy_grid_io.cpp), the ROS
// map_server YAML and the PGM image it names, from memory (parse_occupancy_grid, which the
// file loader calls), then ray casting on what loaded, as the ukf_lrf laser model and the
// simulator's laser cast (OccupancyGrid::cast_ray_along). Input: the YAML text, a line "%%", then
// the image's bytes. It must load a grid or throw MapFileError; any other exception, a crash,
// undefined behaviour, a hang or an allocation out of proportion to the input is a bug. On a
// loaded grid, rays from inside, from its corners and from far outside, with finite and infinite
// ranges: each ends (a hang is a timeout), and a hit is finite, >= 0 and within the range.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "beaconloc/core/occupancy_grid_io.hpp"

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void cast_rays(const beaconloc::OccupancyGrid& grid) {
  const double res = grid.resolution_m();
  const Eigen::Vector2d size(grid.width() * res, grid.height() * res);
  const Eigen::Vector2d o = grid.origin_m();
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d starts[] = {o + size / 2,
                                    o,
                                    o + size,
                                    o + Eigen::Vector2d(res / 2, size.y() - res / 3),
                                    o - 1e3 * size - Eigen::Vector2d(1.0, 1.0),
                                    o + Eigen::Vector2d(1e12, -3e11),
                                    {1e300, -1e300}};
  for (const auto& from : starts) {
    for (int k = 0; k < 16; ++k) {
      const double a = k * M_PI / 8 + 0.1;
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      for (const double range : {8.0, 1e6 * res, inf}) {
        const auto hit = grid.cast_ray_along(from, d, range);
        if (hit) check(std::isfinite(*hit) && *hit >= 0.0 && *hit <= range);
      }
    }
  }
}

}  // namespace

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
    check(grid.width() > 0 && grid.height() > 0 &&
          static_cast<std::size_t>(grid.width()) * static_cast<std::size_t>(grid.height()) <= image.size());
    // The numbers the loader let through are a grid's: within its limits.
    check(grid.resolution_m() >= beaconloc::OccupancyGrid::kMinResolutionM &&
          grid.resolution_m() <= beaconloc::OccupancyGrid::kMaxResolutionM && grid.origin_m().allFinite());
    cast_rays(grid);
  } catch (const beaconloc::MapFileError&) {
  }
  return 0;
}
