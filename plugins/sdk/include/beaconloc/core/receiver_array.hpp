#pragma once
// Positions of the ultrasonic receivers in the robot's base frame (seed 000, eq. 1).
#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace beaconloc {

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
