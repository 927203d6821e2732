#include "pose_bound.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "beaconloc/core/bounds/posterior_crlb.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc {

std::optional<std::string> pose_bound_unsupported(const sim::Scenario& s) {
  if (!s.radio_sync) return "pulse arrivals without firing times (the bound of seed 002 is in its accuracy test)";
  if (!s.local_group_frames_map.empty()) return "locally referenced beacon groups (their frames are not in the bound)";
  if (s.wheel_radius_error_right != 0.0 || s.wheel_radius_error_left != 0.0 || s.wheel_base_error != 0.0) {
    return "systematic wheel errors (a bias is not in the bound)";
  }
  if (s.reported_temperature_c && *s.reported_temperature_c != s.temperature_c) {
    return "a reported temperature off the truth (every range biased)";
  }
  return std::nullopt;
}

std::vector<PoseBoundSample> pose_bound_trace(const sim::Scenario& s, const std::vector<SourceEvent>& events) {
  if (const auto why = pose_bound_unsupported(s)) throw std::invalid_argument("no pose bound: " + *why);
  std::map<std::uint32_t, Eigen::Vector3d> beacons_map_m;
  for (const Beacon& b : s.beacons) beacons_map_m[b.id] = b.position_map_m;
  const double dt_s = ns_to_s(s.odometry_period_ns);
  const double range_variance = sim::range_variance_m2(s);
  // The start known exactly (the file comment): the covariance form takes a zero prior.
  PosteriorCrlb<3> bound(Eigen::Matrix3d::Zero());
  const auto truth_at = [&s](double t_s) -> Eigen::Vector3d { return s.trajectory.pose_at(t_s); };
  const auto check = [](FilterOutcome outcome, const char* step, StampNs stamp_ns) {
    if (outcome != FilterOutcome::kApplied) {
      throw std::runtime_error(std::string("pose bound: the ") + step + " at " + std::to_string(stamp_ns) +
                               " ns was refused");
    }
  };
  std::vector<PoseBoundSample> trace;
  for (const SourceEvent& e : events) {
    const double t_s = ns_to_s(e.stamp_ns);
    if (e.kind == SourceEvent::Kind::kOdometry) {
      double v = 0.0, w = 0.0;
      s.trajectory.mean_velocity(t_s - dt_s, t_s, v, w);
      const Eigen::Vector2d wheels(v + w * s.wheel_base_m / 2.0, v - w * s.wheel_base_m / 2.0);
      const DiffDriveMotion motion(
          s.wheel_base_m, sim::wheel_velocity_covariance(s, wheels(0), wheels(1), s.wheel_base_m, dt_s));
      check(bound.predict(motion, truth_at(t_s - dt_s), wheels, dt_s), "odometry step", e.stamp_ns);
      const Eigen::Matrix3d& p = bound.covariance();
      trace.push_back({e.stamp_ns, p(0, 0) + p(1, 1), p(2, 2)});
    } else if (e.kind == SourceEvent::Kind::kTof && !e.tof_is_echo) {
      const auto beacon = beacons_map_m.find(e.true_beacon_id);
      if (beacon == beacons_map_m.end() || e.tof.receiver_id >= s.receivers.size()) {
        throw std::runtime_error("pose bound: a time of flight from no beacon or receiver of the scenario");
      }
      const RangeModel model(s.receivers.receivers_base_m[e.tof.receiver_id], s.receivers.receiver_height_m,
                             beacon->second, range_variance);
      check(bound.update(model, truth_at(t_s)), "range", e.stamp_ns);
    }
  }
  return trace;
}

std::optional<PoseBoundRms> pose_bound_rms(const std::vector<PoseBoundSample>& trace,
                                           const std::vector<StampNs>& scored_stamps_ns) {
  double position = 0.0, heading = 0.0;
  std::size_t n = 0;
  for (const StampNs stamp_ns : scored_stamps_ns) {
    const auto at = std::lower_bound(trace.begin(), trace.end(), stamp_ns,
                                     [](const PoseBoundSample& b, StampNs t) { return b.stamp_ns < t; });
    if (at == trace.end() || at->stamp_ns != stamp_ns) continue;
    position += at->position_variance_m2;
    heading += at->heading_variance_rad2;
    ++n;
  }
  if (n == 0) return std::nullopt;
  const double count = static_cast<double>(n);
  return PoseBoundRms{std::sqrt(position / count), std::sqrt(heading / count) * 180.0 / M_PI, n};
}

PoseBoundResult pose_bound_of_run(const sim::Scenario& scenario, const std::vector<SourceEvent>& events,
                                  const std::vector<StampNs>& scored_stamps_ns, bool laser_fused) {
  PoseBoundResult out;
  out.laser_fused = laser_fused;
  if (const auto why = pose_bound_unsupported(scenario)) {
    out.unavailable = *why;
    return out;
  }
  out.rms = pose_bound_rms(pose_bound_trace(scenario, events), scored_stamps_ns);
  if (!out.rms) out.unavailable = "no pose scored at an odometry stamp";
  return out;
}

std::string format_pose_bound(const PoseBoundResult& bound, double position_rms_m,
                              std::optional<double> heading_rms_deg) {
  if (!bound.rms) return "posterior Cramer-Rao bound: n/a (" + bound.unavailable + ")";
  char text[256];
  std::snprintf(text, sizeof text, "posterior Cramer-Rao bound over %zu poses: position %.4f m RMS, heading %.3f deg RMS",
                bound.rms->samples, bound.rms->position_m, bound.rms->heading_deg);
  std::string out = text;
  if (bound.laser_fused) return out + " (odometry and ranges; the laser fused here is not in it)";
  std::snprintf(text, sizeof text, "; ours %.2fx", position_rms_m / bound.rms->position_m);
  out += text;
  if (heading_rms_deg) {
    std::snprintf(text, sizeof text, " and %.2fx", *heading_rms_deg / bound.rms->heading_deg);
    out += text;
  }
  return out;
}

}  // namespace beaconloc
