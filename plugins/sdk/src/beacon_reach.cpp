#include "beaconloc/core/beacon_reach.hpp"

#include <cmath>
#include <limits>

#include "beaconloc/core/limits.hpp"

namespace beaconloc {

bool BeaconReach::valid() const {
  if (min_range_m == 0.0 && max_range_m == 0.0 && beam_half_angle_rad == 0.0) return true;
  return std::isfinite(min_range_m) && std::isfinite(max_range_m) && std::isfinite(beam_half_angle_rad) &&
         min_range_m >= 0.0 && min_range_m < max_range_m && max_range_m <= kMaxRangeM &&
         beam_half_angle_rad > 0.0 && beam_half_angle_rad <= M_PI;
}

bool BeaconReach::reaches(const Eigen::Vector3d& beacon_map_m, const Eigen::Vector3d& point_map_m) const {
  if (!known()) return true;
  const Eigen::Vector3d d = point_map_m - beacon_map_m;
  const double range_m = d.norm();
  if (range_m < min_range_m || range_m > max_range_m) return false;
  if (range_m < 1e-9) return true;
  const double cos_off_axis = -d.z() / range_m;  // angle to the beacon's downward axis
  return cos_off_axis >= std::cos(beam_half_angle_rad) - 1e-12;
}

BeaconReach::Annulus BeaconReach::at_drop(double drop_m) const {
  if (!known()) return {0.0, std::numeric_limits<double>::infinity()};
  const double drop2 = drop_m * drop_m;
  Annulus a;
  a.inner_m = std::sqrt(std::max(0.0, min_range_m * min_range_m - drop2));
  const double by_range = max_range_m * max_range_m >= drop2 ? std::sqrt(max_range_m * max_range_m - drop2) : -1.0;
  // The cone: the angle off the downward axis at most the half-angle. Below the beacon (drop > 0)
  // a cone narrower than pi/2 reaches out to drop tan(half) and nothing level or above; a wider
  // one reaches everything below and level, and above the beacon (drop < 0) what lies beyond
  // |drop| tan(pi - half) (nothing above for exactly pi/2, everything for pi).
  double by_beam = std::numeric_limits<double>::infinity();
  if (beam_half_angle_rad < M_PI / 2) {
    by_beam = drop_m > 0.0 ? drop_m * std::tan(beam_half_angle_rad) : -1.0;
  } else if (drop_m < 0.0) {
    if (beam_half_angle_rad == M_PI / 2) return {0.0, -1.0};
    a.inner_m = std::max(a.inner_m, -drop_m * std::tan(M_PI - beam_half_angle_rad));
  }
  a.outer_m = std::min(by_range, by_beam);
  return a;
}

}  // namespace beaconloc
