#include "beaconloc/core/models/range_model.hpp"

#include <cmath>

namespace beaconloc {

RangePrediction predict_range(const Pose2& pose, const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                              const Eigen::Vector3d& beacon_map_m) {
  const double c = std::cos(pose.z()), s = std::sin(pose.z());
  const Eigen::Vector2d receiver_map = transform_point(pose, receiver_base_m);
  const Eigen::Vector3d delta(receiver_map.x() - beacon_map_m.x(), receiver_map.y() - beacon_map_m.y(),
                              receiver_z_m - beacon_map_m.z());
  RangePrediction out;
  out.range_m = delta.norm();
  if (out.range_m < 1e-9) return out;  // receiver at the beacon: gradient undefined, left zero
  // d receiver_map / d yaw = [-s px - c py, c px - s py]
  const double dxr_dyaw = -s * receiver_base_m.x() - c * receiver_base_m.y();
  const double dyr_dyaw = c * receiver_base_m.x() - s * receiver_base_m.y();
  out.jacobian_pose << delta.x() / out.range_m, delta.y() / out.range_m,
      (delta.x() * dxr_dyaw + delta.y() * dyr_dyaw) / out.range_m;
  return out;
}

}  // namespace beaconloc
