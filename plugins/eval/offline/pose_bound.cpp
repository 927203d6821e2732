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

namespace {

// BoundPrior::kNothingKnown: the position anywhere within 100 m, the heading uniform on a turn.
constexpr double kUnknownPositionSigmaM = 100.0;
constexpr double kUnknownHeadingVarianceRad2 = M_PI * M_PI / 3.0;
// A bound at or below this (m, deg) is zero: a noise-free scenario, no ratio to it.
constexpr double kZeroBound = 1e-9;

}  // namespace

std::optional<std::string> pose_bound_unsupported(const sim::Scenario& s) {
  if (!s.radio_sync) return "pulse arrivals without firing times (the bound of seed 002 is in its accuracy test)";
  if (!s.local_group_frames_map.empty()) return "locally referenced beacon groups (their frames are not in the bound)";
  if (s.wheel_radius_error_right != 0.0 || s.wheel_radius_error_left != 0.0 || s.wheel_base_error != 0.0) {
    return "systematic wheel errors (a bias is not in the bound)";
  }
  if (s.range_scale != 1.0 || s.range_bias_m != 0.0) return "a ranging calibration error (every range biased)";
  if (s.reported_temperature_c && *s.reported_temperature_c != s.temperature_c) {
    return "a reported temperature off the truth (every range biased)";
  }
  return std::nullopt;
}

std::vector<PoseBoundSample> pose_bound_trace(const sim::Scenario& s, const std::vector<SourceEvent>& events,
                                              BoundPrior prior) {
  if (const auto why = pose_bound_unsupported(s)) throw std::invalid_argument("no pose bound: " + *why);
  std::map<std::uint32_t, Eigen::Vector3d> beacons_map_m;
  for (const Beacon& b : s.beacons) beacons_map_m[b.id] = b.position_map_m;
  const double dt_s = ns_to_s(s.odometry_period_ns);
  const double range_variance = sim::range_variance_m2(s);
  // The covariance form takes a zero prior: the start known exactly.
  Eigen::Matrix3d p0 = Eigen::Matrix3d::Zero();
  if (prior == BoundPrior::kNothingKnown) {
    p0.diagonal() << kUnknownPositionSigmaM * kUnknownPositionSigmaM, kUnknownPositionSigmaM * kUnknownPositionSigmaM,
        kUnknownHeadingVarianceRad2;
  }
  PosteriorCrlb<3> bound(p0);
  const auto truth_at = [&s](double t_s) -> Eigen::Vector3d { return s.trajectory.pose_at(t_s); };
  const auto check = [](FilterOutcome outcome, const char* step, StampNs stamp_ns) {
    if (outcome != FilterOutcome::kApplied) {
      throw std::runtime_error(std::string("the bound's ") + step + " at " + std::to_string(stamp_ns) +
                               " ns was refused (" + to_string(outcome) + ")");
    }
  };
  const auto close_last = [&bound](std::vector<PoseBoundSample>& trace) {
    if (trace.empty()) return;
    const Eigen::Matrix3d& p = bound.covariance();
    trace.back().corrected_position_variance_m2 = p(0, 0) + p(1, 1);
    trace.back().corrected_heading_variance_rad2 = p(2, 2);
  };
  std::vector<PoseBoundSample> trace;
  for (const SourceEvent& e : events) {
    const double t_s = ns_to_s(e.stamp_ns);
    if (e.kind == SourceEvent::Kind::kOdometry) {
      close_last(trace);
      double v = 0.0, w = 0.0;
      s.trajectory.mean_velocity(t_s - dt_s, t_s, v, w);
      const Eigen::Vector2d wheels = wheel_speeds_mps(v, w, s.wheel_base_m);
      const DiffDriveMotion motion(
          s.wheel_base_m, sim::wheel_velocity_covariance(s, wheels(0), wheels(1), s.wheel_base_m, dt_s));
      check(bound.predict(motion, truth_at(t_s - dt_s), wheels, dt_s), "odometry step", e.stamp_ns);
      const Eigen::Matrix3d& p = bound.covariance();
      trace.push_back({e.stamp_ns, p(0, 0) + p(1, 1), p(2, 2), p(0, 0) + p(1, 1), p(2, 2)});
    } else if (e.kind == SourceEvent::Kind::kTof && !e.tof_is_echo) {
      const auto beacon = beacons_map_m.find(e.true_beacon_id);
      if (beacon == beacons_map_m.end() || e.tof.receiver_id >= s.receivers.size()) {
        throw std::runtime_error("the bound was given a time of flight from no beacon or receiver of the scenario");
      }
      const RangeModel model(s.receivers.receivers_base_m[e.tof.receiver_id], s.receivers.receiver_height_m,
                             beacon->second, range_variance);
      check(bound.update(model, truth_at(t_s)), "range", e.stamp_ns);
    }
  }
  close_last(trace);
  return trace;
}

std::optional<PoseBoundRms> pose_bound_rms(const std::vector<PoseBoundSample>& trace,
                                           const std::vector<StampNs>& scored_stamps_ns, bool corrected) {
  double position = 0.0, heading = 0.0;
  std::size_t n = 0;
  for (const StampNs stamp_ns : scored_stamps_ns) {
    const auto at = std::lower_bound(trace.begin(), trace.end(), stamp_ns,
                                     [](const PoseBoundSample& b, StampNs t) { return b.stamp_ns < t; });
    if (at == trace.end() || at->stamp_ns != stamp_ns) continue;
    position += corrected ? at->corrected_position_variance_m2 : at->position_variance_m2;
    heading += corrected ? at->corrected_heading_variance_rad2 : at->heading_variance_rad2;
    ++n;
  }
  if (n == 0) return std::nullopt;
  const double count = static_cast<double>(n);
  return PoseBoundRms{std::sqrt(position / count), std::sqrt(heading / count) * 180.0 / M_PI, n};
}

PoseBoundResult pose_bound_of_run(const sim::Scenario& scenario, const std::vector<SourceEvent>& events,
                                  const std::vector<StampNs>& scored_stamps_ns, const BoundedEstimator& estimator) {
  PoseBoundResult out;
  out.laser_fused = estimator.laser_fused;
  if (const auto why = pose_bound_unsupported(scenario)) {
    out.unavailable = *why;
    return out;
  }
  try {
    const BoundPrior prior = estimator.localizes_from_beacons ? BoundPrior::kNothingKnown : BoundPrior::kStartKnown;
    out.rms = pose_bound_rms(pose_bound_trace(scenario, events, prior), scored_stamps_ns, estimator.poses_corrected);
  } catch (const std::runtime_error& e) {
    out.unavailable = e.what();
    return out;
  }
  if (!out.rms) out.unavailable = "no pose scored at an odometry stamp";
  return out;
}

std::string bound_ratio(bool laser_fused, bool same_poses, double ours, double bound_value) {
  if (laser_fused) return "n/a (fuses the laser, not in the bound)";
  if (!same_poses) return "n/a (the bound covers other poses than those scored)";
  if (!(bound_value > kZeroBound)) return "n/a (a zero bound: no noise)";
  char text[32];
  std::snprintf(text, sizeof text, "%.2fx", ours / bound_value);
  return text;
}

std::string format_pose_bound(const PoseBoundResult& bound, const Metrics& metrics) {
  if (!bound.rms) return "posterior Cramer-Rao bound: n/a (" + bound.unavailable + ")";
  char text[256];
  std::snprintf(text, sizeof text, "posterior Cramer-Rao bound over %zu poses: position %.4f m RMS, heading %.3f deg RMS",
                bound.rms->samples, bound.rms->position_m, bound.rms->heading_deg);
  std::string out = text;
  if (bound.laser_fused) return out + " (odometry and ranges; the laser fused here is not in it)";
  const bool same_poses = bound.rms->samples == metrics.samples;
  out += "; ours " + bound_ratio(false, same_poses, metrics.position_rms_m, bound.rms->position_m);
  if (metrics.heading_rms_deg) {
    out += " and " + bound_ratio(false, same_poses, *metrics.heading_rms_deg, bound.rms->heading_deg);
  }
  return out;
}

}  // namespace beaconloc
