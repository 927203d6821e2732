#include "beaconloc/core/models/laser_beam_model.hpp"

#include <cmath>

namespace beaconloc {

void expected_laser_ranges(const OccupancyGrid& grid, const Pose2& pose, const LaserBeams& beams,
                           double* out) {
  const Pose2 sensor = compose(pose, beams.mount_base);
  const double c = std::cos(sensor.z()), s = std::sin(sensor.z());
  for (std::size_t i = 0; i < beams.size(); ++i) {
    // The beam's direction in the scanner frame, rotated by the scanner's heading.
    const Eigen::Vector2d& local = beams.directions[i];
    const Eigen::Vector2d direction(c * local.x() - s * local.y(), s * local.x() + c * local.y());
    const auto hit = grid.cast_ray_along(sensor.head<2>(), direction, beams.max_range_m);
    out[i] = hit ? *hit : beams.max_range_m;
  }
}

}  // namespace beaconloc
