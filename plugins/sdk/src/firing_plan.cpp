#include "beaconloc/core/firing_plan.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace beaconloc {

std::vector<std::uint32_t> fire_all(const BeaconMap& map) {
  std::vector<std::uint32_t> ids;
  map.for_each([&ids](const Beacon& b) { ids.push_back(b.id); });
  for (const LocalBeacon& b : map.local_beacons()) ids.push_back(b.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<std::uint32_t> plan_firing(const BeaconMap& map, const ReceiverArray& receivers,
                                       const Pose2& pose, const Cov3& covariance, double sigmas) {
  // A pose that says nothing cannot narrow anything.
  if (!pose.allFinite() || !covariance.allFinite() || !std::isfinite(sigmas)) return fire_all(map);
  // The position's largest standard deviation: the square root of the 2x2 block's largest
  // eigenvalue (self-adjoint solver: no factorization to fail on a singular block).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> position(covariance.topLeftCorner<2, 2>(),
                                                                Eigen::EigenvaluesOnly);
  const double position_sigma_m = std::sqrt(std::max(0.0, position.eigenvalues().maxCoeff()));
  const double yaw_sigma_rad = std::sqrt(std::max(0.0, covariance(2, 2)));
  std::vector<std::uint32_t> plan;
  map.for_each([&](const Beacon& beacon) {
    const BeaconReach reach = map.reach_of(beacon.id);
    if (!reach.known()) {
      plan.push_back(beacon.id);
      return;
    }
    const BeaconReach::Annulus annulus = reach.at_drop(beacon.position_map_m.z() - receivers.receiver_height_m);
    for (const Eigen::Vector2d& receiver_base_m : receivers.receivers_base_m) {
      const Eigen::Vector2d receiver_map_m = transform_point(pose, receiver_base_m);
      const double widen_m = sigmas * (position_sigma_m + receiver_base_m.norm() * std::min(yaw_sigma_rad, M_PI));
      const double foot_m = (receiver_map_m - beacon.position_map_m.head<2>()).norm();
      if (foot_m - widen_m <= annulus.outer_m && foot_m + widen_m >= annulus.inner_m) {
        plan.push_back(beacon.id);
        return;
      }
    }
  });
  if (plan.empty()) return fire_all(map);
  // Locally referenced beacons (seed 003): where they are in the map is not known here, so they
  // are always fired (a group must be heard to be calibrated).
  for (const LocalBeacon& b : map.local_beacons()) plan.push_back(b.id);
  std::sort(plan.begin(), plan.end());
  return plan;
}

}  // namespace beaconloc
