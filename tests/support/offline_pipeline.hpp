#pragma once
// The pipeline without DDS for unit tests (OfflineStack, simulate: plugins/eval/offline), with
// the per-step statistics the tests assert on.
#include <Eigen/Cholesky>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/pose_error.hpp"
#include "offline_run.hpp"

namespace beaconloc::testing {

using beaconloc::OfflineStack;
using beaconloc::simulate;

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
