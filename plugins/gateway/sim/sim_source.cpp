#include "sim_source.hpp"

#include <cmath>

#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc::sim {

double pulse_arrival_s(const Trajectory& trajectory, const Eigen::Vector2d& receiver_base_m,
                       double receiver_z_m, const Eigen::Vector3d& beacon_map_m, double fire_s, double c) {
  double arrival_s = fire_s;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector2d rx = transform_point(trajectory.pose_at(arrival_s), receiver_base_m);
    const double d =
        Eigen::Vector3d(rx.x() - beacon_map_m.x(), rx.y() - beacon_map_m.y(), receiver_z_m - beacon_map_m.z())
            .norm();
    arrival_s = fire_s + d / c;
  }
  return arrival_s;
}

SimSource::SimSource(Scenario scenario, std::uint64_t seed)
    : scenario_(std::move(scenario)),
      rng_(seed),
      next_odometry_ns_(scenario_.odometry_period_ns),
      next_fire_ns_(scenario_.first_slot_ns) {}

void SimSource::fire(StampNs fire_ns) {
  if (scenario_.firing_order.empty()) return;
  const std::uint32_t beacon_id = scenario_.firing_order[slot_ % scenario_.firing_order.size()];
  ++slot_;
  const Beacon* beacon = nullptr;
  for (const auto& b : scenario_.beacons) {
    if (b.id == beacon_id) beacon = &b;
  }
  if (!beacon) return;
  const double c = speed_of_sound_mps(scenario_.temperature_c);
  const double fire_s = ns_to_s(fire_ns);
  for (std::uint32_t rx = 0; rx < scenario_.receivers.size(); ++rx) {
    const double arrival_s =
        pulse_arrival_s(scenario_.trajectory, scenario_.receivers.receivers_base_m[rx],
                        scenario_.receivers.receiver_height_m, beacon->position_map_m, fire_s, c);
    const double true_tof_s = arrival_s - fire_s;
    if (true_tof_s * c > scenario_.max_range_m) continue;  // out of earshot
    SimEvent e;
    e.kind = SimEvent::Kind::kTof;
    e.tof.beacon_id = beacon_id;
    e.tof.receiver_id = rx;
    e.tof.fire_stamp_ns = fire_ns;
    e.tof.tof_s = true_tof_s + scenario_.range_sigma_m / c * unit_normal_(rng_);
    e.tof.beacon_temperature_c = scenario_.temperature_c;
    e.tof.sequence_number = tof_sequence_++;
    e.stamp_ns = fire_ns + s_to_ns(e.tof.tof_s);
    pending_tofs_.push(e);
  }
}

SimEvent SimSource::odometry_at(StampNs stamp_ns) {
  const double dt_s = ns_to_s(scenario_.odometry_period_ns);
  const double t1 = ns_to_s(stamp_ns);
  double v = 0.0, w = 0.0;
  scenario_.trajectory.mean_velocity(t1 - dt_s, t1, v, w);
  const double half_track = scenario_.wheel_base_m / 2.0;
  const double true_right = v + w * half_track, true_left = v - w * half_track;
  // Seed 000: sigma_v^2 = k_v |v| / dT for each wheel.
  auto noisy = [&](double wheel_mps) {
    return wheel_mps + std::sqrt(scenario_.odometry_k_v_m * std::abs(wheel_mps) / dt_s) * unit_normal_(rng_);
  };
  SimEvent e;
  e.kind = SimEvent::Kind::kOdometry;
  e.stamp_ns = stamp_ns;
  e.odometry.stamp_ns = stamp_ns;
  e.odometry.wheel_velocity_right_mps = noisy(true_right);
  e.odometry.wheel_velocity_left_mps = noisy(true_left);
  e.odometry.wheel_base_m = scenario_.wheel_base_m;
  // The robot reports the noise model evaluated at what it measured (it cannot know the truth).
  e.odometry.wheel_velocity_covariance.diagonal()
      << scenario_.odometry_k_v_m * std::abs(e.odometry.wheel_velocity_right_mps) / dt_s,
      scenario_.odometry_k_v_m * std::abs(e.odometry.wheel_velocity_left_mps) / dt_s;
  e.truth_map_base = scenario_.trajectory.pose_at(t1);
  return e;
}

void SimSource::advance(StampNs until_ns, std::vector<SimEvent>& out) {
  for (;;) {
    const StampNs next_tof = pending_tofs_.empty() ? until_ns + 1 : pending_tofs_.top().stamp_ns;
    const StampNs next = std::min({next_odometry_ns_, next_fire_ns_, next_tof});
    if (next > until_ns) return;
    if (next == next_fire_ns_) {
      fire(next_fire_ns_);
      next_fire_ns_ += scenario_.slot_period_ns;
    } else if (next == next_tof) {
      out.push_back(pending_tofs_.top());
      pending_tofs_.pop();
    } else {
      out.push_back(odometry_at(next_odometry_ns_));
      next_odometry_ns_ += scenario_.odometry_period_ns;
    }
  }
}

}  // namespace beaconloc::sim
