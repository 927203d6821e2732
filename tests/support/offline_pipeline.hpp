#pragma once
// The pipeline without DDS, for unit and accuracy tests: simulated source -> TofDecoder ->
// LocalizerCore, with every pose compared to the simulator's truth.
#include <Eigen/Cholesky>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/pose_error.hpp"
#include "localizer_core.hpp"
#include "sim/sim_source.hpp"
#include "tof_decoder.hpp"

namespace beaconloc::testing {

inline std::vector<SourceEvent> simulate(const sim::Scenario& scenario, std::uint64_t seed,
                                         double duration_s) {
  sim::SimSource source(scenario, seed);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(duration_s), events);
  return events;
}

// Decoder and localizer cores wired as the participants wire them, knowing the scenario's map.
struct OfflineStack {
  explicit OfflineStack(const sim::Scenario& scenario, const std::string& estimator = "range_ekf")
      : localizer(estimator, config_for(scenario)) {
    localizer.set_beacon_map(BeaconMap(scenario.beacons));
    decoder.set_beacon_map(BeaconMap(scenario.beacons));
  }
  // One simulated event in; the pose the localizer would publish, on odometry events.
  std::optional<LocalizerOutput> feed(const std::string& robot_id, const SourceEvent& e) {
    if (e.kind == SourceEvent::Kind::kTof) {
      if (const auto out = decoder.decode(robot_id, e.tof); out.range) {
        localizer.on_range(robot_id, out.range->range);
      }
      return std::nullopt;
    }
    if (e.kind != SourceEvent::Kind::kOdometry) return std::nullopt;
    return localizer.on_odometry(robot_id, e.odometry);
  }
  static EstimatorConfig config_for(const sim::Scenario& scenario) {
    EstimatorConfig config;
    config.receivers = scenario.receivers;
    return config;
  }

  LocalizerCore localizer;
  TofDecoder decoder;
};

struct OfflineRun {
  PoseErrorAccumulator error;  // over every pose after start_after_s + settle_s
  std::size_t poses = 0;
  std::size_t nees_steps = 0;
  std::size_t nees_in_band = 0;  // NEES (3 dof) within the two-sided 95 % chi-square band
  double first_pose_s = -1.0;    // sim time of the first pose
  RejectionCounter decoder_counts;
  RejectionCounter localizer_counts;

  double nees_in_band_fraction() const {
    return nees_steps ? static_cast<double>(nees_in_band) / static_cast<double>(nees_steps) : 0.0;
  }
};

inline OfflineRun run_offline(const sim::Scenario& scenario, std::uint64_t seed, double duration_s,
                              const std::string& estimator = "range_ekf", double start_after_s = 0.0,
                              double settle_s = 2.0) {
  OfflineStack stack(scenario, estimator);
  OfflineRun run;
  const StampNs start_ns = s_to_ns(start_after_s);
  for (const auto& e : simulate(scenario, seed, duration_s)) {
    if (e.stamp_ns < start_ns) continue;  // a localizer that joins late has seen nothing before
    const auto pose = stack.feed("robot", e);
    if (!pose) continue;
    ++run.poses;
    if (run.first_pose_s < 0.0) run.first_pose_s = ns_to_s(e.stamp_ns);
    if (e.stamp_ns < start_ns + s_to_ns(settle_s)) continue;
    const Pose2& est = pose->estimate.pose_map_base;
    run.error.add(e.truth_map_base, est);
    Eigen::Vector3d err = e.truth_map_base - est;
    err.z() = wrap_angle_rad(err.z());
    const double nees = err.dot(pose->estimate.covariance.ldlt().solve(err));
    ++run.nees_steps;
    // chi-square, 3 dof: 2.5 % and 97.5 % quantiles
    if (nees >= 0.2158 && nees <= 9.3484) ++run.nees_in_band;
  }
  run.decoder_counts = stack.decoder.counts();
  run.localizer_counts = stack.localizer.counts();
  return run;
}

}  // namespace beaconloc::testing
