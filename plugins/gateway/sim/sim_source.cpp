#include "sim_source.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "beaconloc/core/models/diff_drive_motion.hpp"
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

bool hears(const Scenario& s, const Eigen::Vector3d& beacon, const Eigen::Vector3d& receiver) {
  return s.reach().reaches(beacon, receiver);
}

// What a receiver without the beacons' radio message reports of a pulse (seed 002 Sec. 2): when it
// arrived, in the robot's clock (the simulator's), and whether it came as a double burst.
static SourceEvent as_pulse_arrival(SourceEvent tof, std::optional<std::uint32_t> marked_beacon_id) {
  SourceEvent e = std::move(tof);
  e.kind = SourceEvent::Kind::kPulse;
  e.pulse.stamp_ns = e.stamp_ns;
  e.pulse.receiver_id = e.tof.receiver_id;
  e.pulse.mark = marked_beacon_id && *marked_beacon_id == e.true_beacon_id ? PulseMark::kDouble : PulseMark::kSingle;
  e.pulse.sequence_number = e.tof.sequence_number;
  e.tof = RawTofSample{};
  return e;
}

SimSource::SimSource(Scenario scenario, std::uint64_t seed)
    : scenario_(std::move(scenario)),
      rng_(seed),
      next_odometry_ns_(scenario_.odometry_period_ns),
      next_fire_ns_(scenario_.first_slot_ns),
      next_scan_ns_(scenario_.laser ? scenario_.laser->period_ns : std::numeric_limits<StampNs>::max()),
      group_centres_map_m_(scenario_.group_centres_map_m()) {
  // LaserModel::systematic_error_m: each beam's fixed error, drawn once (only when there is one,
  // so that the random stream of every other scenario is as it was).
  if (scenario_.laser && scenario_.laser->systematic_error_m > 0.0) {
    for (int i = 0; i < scenario_.laser->beams; ++i) {
      beam_errors_m_.push_back(scenario_.laser->systematic_error_m * (2.0 * uniform() - 1.0));
    }
  }
}

void SimSource::set_firing_plan(std::optional<std::vector<std::uint32_t>> beacon_ids) {
  if (beacon_ids) {
    std::vector<std::uint32_t>& ids = *beacon_ids;
    ids.erase(std::remove_if(ids.begin(), ids.end(),
                             [this](std::uint32_t id) {
                               return std::none_of(scenario_.beacons.begin(), scenario_.beacons.end(),
                                                   [id](const Beacon& b) { return b.id == id; });
                             }),
              ids.end());
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    if (ids.empty()) beacon_ids.reset();
  }
  plan_ = std::move(beacon_ids);
}

std::uint32_t SimSource::next_beacon() {
  if (!plan_) return scenario_.firing_order[slot_ % scenario_.firing_order.size()];
  // The plan's next id after the last one fired, so that a plan refreshed every slot still
  // fires each of its beacons in turn.
  const auto after = last_fired_id_ ? std::upper_bound(plan_->begin(), plan_->end(), *last_fired_id_)
                                    : plan_->begin();
  return after == plan_->end() ? plan_->front() : *after;
}

void SimSource::fire(StampNs fire_ns) {
  if (scenario_.firing_order.empty()) return;
  const std::uint32_t beacon_id = next_beacon();
  ++slot_;
  last_fired_id_ = beacon_id;
  const Beacon* beacon = nullptr;
  for (const auto& b : scenario_.beacons) {
    if (b.id == beacon_id) beacon = &b;
  }
  if (!beacon) return;
  ++counts_.fired;
  bool heard = false;
  const double c = speed_of_sound_mps(scenario_.temperature_c);
  const double fire_s = ns_to_s(fire_ns);
  const bool announces_id =
      scenario_.identified || (scenario_.marked_beacon_id && *scenario_.marked_beacon_id == beacon_id);
  for (std::uint32_t rx = 0; rx < scenario_.receivers.size(); ++rx) {
    const Eigen::Vector2d& rx_base = scenario_.receivers.receivers_base_m[rx];
    const double rx_z = scenario_.receivers.receiver_height_m;
    const double arrival_s =
        pulse_arrival_s(scenario_.trajectory, rx_base, rx_z, beacon->position_map_m, fire_s, c);
    const Eigen::Vector2d rx_map = transform_point(scenario_.trajectory.pose_at(arrival_s), rx_base);
    if (!hears(scenario_, beacon->position_map_m, {rx_map.x(), rx_map.y(), rx_z})) continue;
    if (scenario_.group_coverage_radius_m && beacon->group != 0 &&
        (rx_map - group_centres_map_m_.at(beacon->group)).norm() > *scenario_.group_coverage_radius_m)
      continue;
    SourceEvent e;
    e.kind = SourceEvent::Kind::kTof;
    e.true_beacon_id = beacon_id;
    e.tof.beacon_id = announces_id ? beacon_id : kBeaconUnidentified;
    e.tof.receiver_id = rx;
    e.tof.fire_stamp_ns = fire_ns;
    e.tof.tof_s =
        arrival_s - fire_s + scenario_.range_sigma_m / c * normal() + scenario_.tof_sigma_s * normal();
    if (scenario_.range_scale != 1.0 || scenario_.range_bias_m != 0.0) {  // the clean path stays bit for bit
      e.tof.tof_s += ((scenario_.range_scale - 1.0) * (arrival_s - fire_s) * c + scenario_.range_bias_m) / c;
    }
    if (scenario_.echo.probability > 0.0 && uniform() < scenario_.echo.probability) {
      const auto& echo = scenario_.echo;
      e.tof.tof_s +=
          (echo.min_extra_path_m + uniform() * (echo.max_extra_path_m - echo.min_extra_path_m)) / c;
      e.tof_is_echo = true;
    }
    e.tof.beacon_temperature_c = scenario_.reported_temperature_c.value_or(scenario_.temperature_c);
    e.tof.sequence_number = tof_sequence_++;
    e.stamp_ns = fire_ns + s_to_ns(e.tof.tof_s);
    // A silenced firing draws the same noise, so that a run with a dead beacon or an outage
    // differs from the clean run of its seed by the fault alone. (Echoes draw more random
    // numbers: with echoes=P the rest of the noise is another draw of the same statistics.)
    if (scenario_.faults.silences(beacon_id, fire_ns)) {
      --tof_sequence_;
      continue;
    }
    if (!scenario_.radio_sync) e = as_pulse_arrival(std::move(e), scenario_.marked_beacon_id);
    pending_tofs_.push(e);
    heard = true;
  }
  if (heard) ++counts_.heard;
  if (firings_.size() >= kMaxFiringLog) firings_.erase(firings_.begin(), firings_.begin() + kMaxFiringLog / 2);
  firings_.push_back({fire_ns, beacon_id, plan_.has_value(), heard});
}

SourceEvent SimSource::odometry_at(StampNs stamp_ns) {
  const double dt_s = ns_to_s(scenario_.odometry_period_ns);
  const double t1 = ns_to_s(stamp_ns);
  double v = 0.0, w = 0.0;
  scenario_.trajectory.mean_velocity(t1 - dt_s, t1, v, w);
  const double reported_base = scenario_.wheel_base_m * (1.0 + scenario_.wheel_base_error);
  SourceEvent e;
  e.kind = SourceEvent::Kind::kOdometry;
  e.stamp_ns = stamp_ns;
  e.odometry.stamp_ns = stamp_ns;
  e.odometry.wheel_base_m = reported_base;
  // Systematic errors (wheel radii) scale what the encoders report.
  const Eigen::Vector2d wheels_mps = wheel_speeds_mps(v, w, scenario_.wheel_base_m);
  double right = wheels_mps(0) * (1.0 + scenario_.wheel_radius_error_right);
  double left = wheels_mps(1) * (1.0 + scenario_.wheel_radius_error_left);
  if (scenario_.odometry_alpha) {
    // Seed 001 eq. 6: noise on the velocities the robot reports, (v, w) from its wheels.
    const auto variances = [this](double lin, double ang) {
      return alpha_velocity_variances(*scenario_.odometry_alpha, lin, ang);
    };
    double v_meas = (right + left) / 2.0, w_meas = (right - left) / reported_base;
    const Eigen::Vector2d true_var = variances(v_meas, w_meas);
    v_meas += std::sqrt(true_var.x()) * normal();
    w_meas += std::sqrt(true_var.y()) * normal();
    right = v_meas + w_meas * reported_base / 2.0;
    left = v_meas - w_meas * reported_base / 2.0;
    // Reported: the model at what was measured, carried to the wheels by
    // [v_R, v_L] = [[1, B/2], [1, -B/2]] [v, w].
    Eigen::Matrix2d to_wheels;
    to_wheels << 1.0, reported_base / 2.0, 1.0, -reported_base / 2.0;
    e.odometry.wheel_velocity_covariance =
        to_wheels * variances(v_meas, w_meas).asDiagonal() * to_wheels.transpose();
  } else {
    // Seed 000: sigma_v^2 = k_v |v| / dT for each wheel, reported at what was measured.
    const Eigen::Matrix2d drawn = wheel_velocity_covariance(scenario_, right, left, reported_base, dt_s);
    right += std::sqrt(drawn(0, 0)) * normal();
    left += std::sqrt(drawn(1, 1)) * normal();
    e.odometry.wheel_velocity_covariance = wheel_velocity_covariance(scenario_, right, left, reported_base, dt_s);
  }
  e.odometry.wheel_velocity_right_mps = right;
  e.odometry.wheel_velocity_left_mps = left;
  e.has_truth = true;
  e.truth_map_base = scenario_.trajectory.pose_at(t1);
  return e;
}

SourceEvent SimSource::scan_at(StampNs stamp_ns) {
  const LaserModel& laser = *scenario_.laser;
  const Pose2 sensor = compose(scenario_.trajectory.pose_at(ns_to_s(stamp_ns)), laser.mount_base);
  SourceEvent e;
  e.kind = SourceEvent::Kind::kLaserScan;
  e.stamp_ns = stamp_ns;
  e.scan.stamp_ns = stamp_ns;
  const double increment = laser.beams > 1 ? laser.fov_rad / (laser.beams - 1) : 0.0;
  e.scan.angle_min_rad = static_cast<float>(-laser.fov_rad / 2.0);
  e.scan.angle_increment_rad = static_cast<float>(increment);
  e.scan.range_min_m = 0.0f;
  e.scan.range_max_m = static_cast<float>(laser.max_range_m);
  const OccupancyGrid& world = scenario_.world ? *scenario_.world : *scenario_.map;
  const std::vector<Disc> people = discs_at(scenario_.people, ns_to_s(stamp_ns));
  for (int i = 0; i < laser.beams; ++i) {
    const double angle = sensor.z() - laser.fov_rad / 2.0 + i * increment;
    const auto hit = spot_reading_m(world, people, laser.spot, sensor.head<2>(), angle, laser.max_range_m);
    const double noise = normal();  // drawn for every beam: the stream does not depend on hits
    const double systematic_m = beam_errors_m_.empty() ? 0.0 : beam_errors_m_[static_cast<std::size_t>(i)];
    e.scan.ranges_m.push_back(
        hit ? static_cast<float>(std::max(0.0, *hit + systematic_m + laser.range_sigma_m * noise))
            : std::numeric_limits<float>::infinity());
  }
  return e;
}

void SimSource::advance(StampNs until_ns, std::vector<SourceEvent>& out) {
  for (;;) {
    const StampNs next_tof = pending_tofs_.empty() ? until_ns + 1 : pending_tofs_.top().stamp_ns;
    const StampNs next = std::min({next_odometry_ns_, next_fire_ns_, next_tof, next_scan_ns_});
    if (next > until_ns) return;
    if (next == next_fire_ns_) {
      fire(next_fire_ns_);
      next_fire_ns_ += scenario_.slot_period_ns;
    } else if (next == next_tof) {
      out.push_back(pending_tofs_.top());
      pending_tofs_.pop();
    } else if (next == next_odometry_ns_) {
      out.push_back(odometry_at(next_odometry_ns_));
      next_odometry_ns_ += scenario_.odometry_period_ns;
    } else {
      out.push_back(scan_at(next_scan_ns_));
      next_scan_ns_ += scenario_.laser->period_ns;
    }
  }
}

}  // namespace beaconloc::sim
