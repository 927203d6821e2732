#pragma once
// Positions of the ultrasonic receivers in the robot's base frame (seed 000, eq. 1).
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "beaconloc/core/time.hpp"

namespace beaconloc {

// Two receivers' ranges to one firing arrive within this of each other: within the time sound
// takes to cross the robot (0.4 m / 343 m/s = 1.2 ms), far less than the 100-200 ms between two
// firings.
inline constexpr StampNs kSameFiringNs = 20 * kNsPerMillisecond;
// Slack of the triangle inequality below, in sigmas of the two ranges' difference.
inline constexpr double kTriangleSlackSigma = 3.0;

// Echoes, told by geometry alone: two receivers baseline_m apart hearing one firing measure
// ranges that differ by at most baseline_m (triangle inequality). An echo's path is longer: of a
// pair that differs by more, the longer range is the echo. False also for a non-finite range.
inline bool ranges_of_one_firing_agree(double range_a_m, double range_b_m, double baseline_m,
                                       double variance_sum_m2) {
  return std::abs(range_a_m - range_b_m) <= baseline_m + kTriangleSlackSigma * std::sqrt(variance_sum_m2);
}

struct ReceiverArray {
  std::vector<Eigen::Vector2d> receivers_base_m;  // index = receiver id
  double receiver_height_m = 0.0;                 // seed 000 assumes receivers at z = 0

  std::size_t size() const { return receivers_base_m.size(); }

  // Seed 000 eq. 1: receiver l at r_R [cos g_l, sin g_l] with g_l = 2 pi (l - 1) / count.
  static ReceiverArray on_circle(double radius_m, int count) {
    ReceiverArray a;
    for (int l = 0; l < count; ++l) {
      const double g = 2.0 * M_PI * l / count;
      a.receivers_base_m.emplace_back(radius_m * std::cos(g), radius_m * std::sin(g));
    }
    return a;
  }
};

}  // namespace beaconloc
