#pragma once
// Where a beacon's pulse can be heard (seed 004 Sec. 4: the SRF04's "beam width of 30 degrees from
// the center" and "distance range of 5 m ~ 3.5 m"): a slant range window and a cone around the
// beacon's downward axis. The simulator hears by it, and the firing plan (core/firing_plan.hpp)
// fires only the beacons that may reach the robot. A beacon whose reach is not known (a map from a
// file that does not say) reaches everywhere: it is never left out of a plan.
#include <Eigen/Core>

namespace beaconloc {

struct BeaconReach {
  double min_range_m = 0.0;          // slant range window [min, max]
  double max_range_m = 0.0;          // 0: reach not known
  double beam_half_angle_rad = 0.0;  // cone around the downward axis, in (0, pi]

  bool known() const { return max_range_m > 0.0; }
  // Finite numbers with 0 <= min < max <= kMaxRangeM and a half-angle in (0, pi], or all three
  // zero (not known).
  bool valid() const;
  // Whether a point at point_map_m hears a beacon at beacon_map_m; true where not known.
  bool reaches(const Eigen::Vector3d& beacon_map_m, const Eigen::Vector3d& point_map_m) const;

  // The horizontal distances from the beacon's foot at which a point drop_m below it hears it:
  // [inner, outer], empty when outer < inner. Unbounded (outer = +inf) where not known.
  struct Annulus {
    double inner_m = 0.0;
    double outer_m = 0.0;
  };
  Annulus at_drop(double drop_m) const;

  bool operator==(const BeaconReach& o) const {
    return min_range_m == o.min_range_m && max_range_m == o.max_range_m &&
           beam_half_angle_rad == o.beam_half_angle_rad;
  }
  bool operator!=(const BeaconReach& o) const { return !(*this == o); }
};

}  // namespace beaconloc
