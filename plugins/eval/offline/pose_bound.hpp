#pragma once
// The posterior Cramer-Rao bound (core/bounds/posterior_crlb.hpp) of the robot's pose along a
// simulated scenario's true trajectory, from the scenario's own noise models: the odometry's
// wheel noise at the true wheel speeds (seed 000's k_v or seed 001's alpha), each direct time of
// flight a receiver heard as one range of the range noise (range_variance_m2), measured by the
// receiver that heard it, from the beacon that fired. It is what the data allow: no unbiased
// estimator of the pose from the same odometry and ranges has a smaller mean square error, on
// average over the noise (docs/bound.md).
// What it assumes, to say beside any figure it gives:
//  - the start pose is known exactly (as the estimators placed by hand are told it; one that
//    finds itself from the beacons knows less, so the bound stays a bound for it);
//  - echoes are recognised and left out, and a range's beacon is known (an anonymous range's
//    association is given): the bound is for the direct ranges alone;
//  - the laser is not in it: an estimator fusing scans may go below it;
//  - each range is taken at the pose of the last odometry sample's step, linearized at the true
//    pose at its arrival (the robot moves under 4 mm between samples at 100 Hz and 0.34 m/s).
// DDS-free, for `beaconloc accuracy` and `run`.
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/time.hpp"
#include "sim/scenario.hpp"
#include "source.hpp"

namespace beaconloc {

// Why the bound cannot follow this scenario (a cause of error the bound does not model), or
// nullopt when it can: pulse arrivals without firing times (seed 002 has its own bound, in its
// accuracy test), locally referenced beacon groups (frames unknown to the robot), systematic
// wheel errors, a reported temperature off the truth.
std::optional<std::string> pose_bound_unsupported(const sim::Scenario& scenario);

// The bound on the pose error's covariance after each odometry sample.
struct PoseBoundSample {
  StampNs stamp_ns = 0;
  double position_variance_m2 = 0.0;       // trace of the (x, y) block
  double heading_variance_rad2 = 0.0;
};

// The bound along the scenario's events (as simulate() gives them, in stamp order). Throws
// std::invalid_argument when the scenario is unsupported (the reason), std::runtime_error when
// a step of the recursion is refused (a non-finite number, an innovation not positive definite).
std::vector<PoseBoundSample> pose_bound_trace(const sim::Scenario& scenario, const std::vector<SourceEvent>& events);

// Root mean square of the bound's sigmas over the stamps scored: sqrt(mean trace P_xy), and
// sqrt(mean P_yaw) in degrees, as E_p RMS and E_phi RMS are. nullopt when no stamp is in the trace.
struct PoseBoundRms {
  double position_m = 0.0;
  double heading_deg = 0.0;
  std::size_t samples = 0;
};
std::optional<PoseBoundRms> pose_bound_rms(const std::vector<PoseBoundSample>& trace,
                                           const std::vector<StampNs>& scored_stamps_ns);

// A run's bound, or why it has none: what `accuracy` and `run` print.
struct PoseBoundResult {
  std::optional<PoseBoundRms> rms;
  std::string unavailable;   // why there is no bound, when rms is empty
  bool laser_fused = false;  // the estimator fused scans: the bound (no laser in it) is no bound for it
};
// The bound of one run: the scenario's events up to its end (simulate()), the stamps of the
// poses scored, and whether the estimator fused the laser.
PoseBoundResult pose_bound_of_run(const sim::Scenario& scenario, const std::vector<SourceEvent>& events,
                                  const std::vector<StampNs>& scored_stamps_ns, bool laser_fused);
// One line for `run`: the bound and our ratios to it ("bound: ..."), or why there is none.
std::string format_pose_bound(const PoseBoundResult& bound, double position_rms_m,
                              std::optional<double> heading_rms_deg);

}  // namespace beaconloc
