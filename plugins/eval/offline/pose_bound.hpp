#pragma once
// The posterior Cramer-Rao bound (core/bounds/posterior_crlb.hpp) of the robot's pose along a
// simulated scenario's true trajectory, from the scenario's own noise models: the odometry's
// wheel noise at the true wheel speeds (seed 000's k_v or seed 001's alpha), each direct time of
// flight a receiver heard as one range of the range noise (range_variance_m2), measured by the
// receiver that heard it, from the beacon that fired. It is what the data allow: no unbiased
// estimator of the pose from the same odometry and ranges has a smaller mean square error, on
// average over the noise and the prior (a Bayesian bound: it holds for any estimator, biased or
// not, to the approximation below), docs/bound.md.
// What it assumes, to say beside any figure it gives:
//  - what the estimator knows of the start (BoundPrior): the start pose exactly, for the
//    estimators placed by hand; next to nothing for those that find themselves from the beacons;
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
#include "evaluation.hpp"
#include "sim/scenario.hpp"
#include "source.hpp"

namespace beaconloc {

// Why the bound cannot follow this scenario (a cause of error the bound does not model), or
// nullopt when it can: pulse arrivals without firing times (seed 002 has its own bound, in its
// accuracy test), locally referenced beacon groups (frames unknown to the robot), systematic
// wheel errors, a reported temperature off the truth.
std::optional<std::string> pose_bound_unsupported(const sim::Scenario& scenario);

// What the estimator knows of the pose before any data: the start exactly (placed by hand), or
// next to nothing (a position anywhere within 100 m, any heading: one that finds itself).
enum class BoundPrior { kStartKnown, kNothingKnown };

// The bound on the pose error's covariance at each odometry sample: right after its step, and
// with the ranges heard until the next one (what a pose at that stamp corrected by them knows:
// `run` keeps the newest pose per stamp).
struct PoseBoundSample {
  StampNs stamp_ns = 0;
  double position_variance_m2 = 0.0;  // trace of the (x, y) block, after the step
  double heading_variance_rad2 = 0.0;
  double corrected_position_variance_m2 = 0.0;  // the same with the ranges until the next step
  double corrected_heading_variance_rad2 = 0.0;
};

// The bound along the scenario's events (as simulate() gives them, in stamp order). Throws
// std::invalid_argument when the scenario is unsupported (the reason), std::runtime_error when
// a step of the recursion is refused (a non-finite number, an innovation not positive definite).
std::vector<PoseBoundSample> pose_bound_trace(const sim::Scenario& scenario, const std::vector<SourceEvent>& events,
                                              BoundPrior prior = BoundPrior::kStartKnown);

// Root mean square of the bound's sigmas over the stamps scored: sqrt(mean trace P_xy), and
// sqrt(mean P_yaw) in degrees, as E_p RMS and E_phi RMS are. nullopt when no stamp is in the trace.
struct PoseBoundRms {
  double position_m = 0.0;
  double heading_deg = 0.0;
  std::size_t samples = 0;
};
// corrected: the bound with the ranges until the next step (a pose replaced by its corrections).
std::optional<PoseBoundRms> pose_bound_rms(const std::vector<PoseBoundSample>& trace,
                                           const std::vector<StampNs>& scored_stamps_ns, bool corrected = false);

// A run's bound, or why it has none: what `accuracy` and `run` print.
struct PoseBoundResult {
  std::optional<PoseBoundRms> rms;
  std::string unavailable;   // why there is no bound, when rms is empty
  bool laser_fused = false;  // the estimator fused scans: the bound (no laser in it) is no bound for it
};
// What a run's estimator is, for its bound.
struct BoundedEstimator {
  bool laser_fused = false;            // LocalizerCore::uses_laser
  bool localizes_from_beacons = true;  // LocalizerCore::localizes_from_beacons: BoundPrior
  bool poses_corrected = false;        // its pose at a stamp is replaced by the ranges' corrections (run)
};
// The bound of one run: the scenario's events up to its end (simulate()) and the stamps of the
// poses scored. A scenario the bound does not follow, or a step of it refused, is a reason in
// `unavailable`, never an exception.
PoseBoundResult pose_bound_of_run(const sim::Scenario& scenario, const std::vector<SourceEvent>& events,
                                  const std::vector<StampNs>& scored_stamps_ns, const BoundedEstimator& estimator);
// The ratio of ours to the bound, "1.23x", or why there is none: the estimator fuses the laser,
// the bound covers other poses than those scored, or it is zero (a noise-free scenario).
std::string bound_ratio(bool laser_fused, bool same_poses, double ours, double bound_value);
// One line for `run`: the bound and our ratios to it, or why there is none.
std::string format_pose_bound(const PoseBoundResult& bound, const Metrics& metrics);

}  // namespace beaconloc
