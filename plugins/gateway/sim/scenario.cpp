#include "scenario.hpp"

#include <cmath>
#include <optional>
#include <utility>

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc::sim {

Scenario default_scenario() {
  Scenario s;
  s.name = "default";
  s.description = "seed 000 setup (six Txs at 2.011 m, three Rxs on a 0.19 m circle), stadium loop";
  const double z_t = 2.011;  // seed 000, trajectories 1-2
  std::uint32_t id = 1;
  for (double y : {-0.3, 1.5}) {
    for (double x : {0.0, 1.5, 3.0}) {
      s.beacons.push_back({id, {x, y, z_t}, 0});
      s.firing_order.push_back(id);
      ++id;
    }
  }
  s.receivers = ReceiverArray::on_circle(0.19, 3);  // seed 000 eq. 1, r_R = 0.19 m
  // Pioneer P3-DX (the paper's robot); the paper does not print B_w: 0.33 m is the P3-DX's
  // nominal wheel track (assumption).
  s.wheel_base_m = 0.33;
  const double v = 0.34, turn_radius = 0.6, straight = 2.0;
  const double w = v / turn_radius;
  s.trajectory = Trajectory(
      {0.5, 0.0, 0.0}, {{straight / v, v, 0.0}, {M_PI / w, v, w}, {straight / v, v, 0.0}, {M_PI / w, v, w}},
      /*loop=*/true);
  return s;
}

BeaconList Scenario::beacon_list() const {
  BeaconList list;
  for (const Beacon& b : beacons) {
    const auto frame = local_group_frames_map.find(b.group);
    if (frame == local_group_frames_map.end()) {
      list.map_frame.push_back(b);
      continue;
    }
    const Pose2 in_group = between(frame->second, {b.position_map_m.x(), b.position_map_m.y(), 0.0});
    list.group_frame.push_back({b.id, b.group, {in_group.x(), in_group.y(), b.position_map_m.z()}});
  }
  for (const Beacon& b : beacons) list.reach[b.id] = reach();
  return list;
}

std::map<std::uint32_t, Eigen::Vector2d> Scenario::group_centres_map_m() const {
  std::map<std::uint32_t, std::pair<Eigen::Vector2d, int>> sums;  // group -> (sum of x, y; beacons)
  for (const Beacon& b : beacons) {
    auto& [sum, count] = sums.try_emplace(b.group, Eigen::Vector2d::Zero(), 0).first->second;
    sum += b.position_map_m.head<2>();
    ++count;
  }
  std::map<std::uint32_t, Eigen::Vector2d> centres;
  for (const auto& [group, sum_count] : sums) centres[group] = sum_count.first / sum_count.second;
  return centres;
}

bool Scenario::nearest_group_is_local(double x_map_m, double y_map_m) const {
  const Eigen::Vector2d p(x_map_m, y_map_m);
  std::optional<std::uint32_t> nearest;
  double nearest_m = INFINITY;
  for (const auto& [group, centre] : group_centres_map_m()) {
    const double d_m = (centre - p).norm();
    if (d_m < nearest_m) {
      nearest_m = d_m;
      nearest = group;
    }
  }
  return nearest && local_group_frames_map.count(*nearest) > 0;
}

Eigen::Vector2d alpha_velocity_variances(const std::array<double, 4>& alpha, double linear_mps, double angular_radps) {
  return {alpha[0] * linear_mps * linear_mps + alpha[1] * angular_radps * angular_radps,
          alpha[2] * linear_mps * linear_mps + alpha[3] * angular_radps * angular_radps};
}

Eigen::Matrix2d wheel_velocity_covariance(const Scenario& scenario, double right_mps, double left_mps,
                                          double wheel_base_m, double dt_s) {
  if (scenario.odometry_alpha) {
    const double v = (right_mps + left_mps) / 2.0, w = (right_mps - left_mps) / wheel_base_m;
    const Eigen::Matrix2d to_wheels = wheel_speeds_per_twist(wheel_base_m);
    return to_wheels * alpha_velocity_variances(*scenario.odometry_alpha, v, w).asDiagonal() * to_wheels.transpose();
  }
  Eigen::Matrix2d c = Eigen::Matrix2d::Zero();
  c.diagonal() << scenario.odometry_k_v_m * std::abs(right_mps) / dt_s, scenario.odometry_k_v_m * std::abs(left_mps) / dt_s;
  return c;
}

double range_variance_m2(const Scenario& scenario) {
  const double c = speed_of_sound_mps(scenario.temperature_c);
  return scenario.range_sigma_m * scenario.range_sigma_m + c * c * scenario.tof_sigma_s * scenario.tof_sigma_s;
}

bool Faults::silences(std::uint32_t beacon_id, StampNs fire_ns) const {
  const auto dead = beacon_dies_at_ns.find(beacon_id);
  if (dead != beacon_dies_at_ns.end() && fire_ns >= dead->second) return true;
  for (const auto& [from_ns, to_ns] : tof_outages_ns) {
    if (fire_ns >= from_ns && fire_ns < to_ns) return true;
  }
  return false;
}

}  // namespace beaconloc::sim
