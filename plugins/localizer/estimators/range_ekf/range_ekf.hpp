#pragma once
// range_ekf: EKF on [x, y, yaw], predicted by wheel odometry (seed 000 eq. 14, 16) and updated
// by each range on its own (3D range from a receiver to a ceiling beacon of known height), with
// NIS gating. Initialized by a global range-only fix (core/solvers/range_pose_solver) over a
// window of ranges, each moved to the current pose through the dead-reckoned odometry, once the
// fix is unambiguous and certain enough. Watched for divergence over the recent ranges: a pose
// they contradict is degraded and, when a global fix confirms it is wrong, re-initialized.
// With range_calibration 1 or 2 the ranges' scale and bias are estimated with the pose
// (range_calibration.hpp): the state grows to [x, y, yaw, scale, bias, ...].
#include <deque>
#include <optional>

#include "beaconloc/core/chi_square.hpp"
#include "beaconloc/core/estimator_base.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/filters/ekf.hpp"
#include "beaconloc/core/models/range_noise_scale.hpp"
#include "beaconloc/core/solvers/range_pose_solver.hpp"
#include "range_ekf/range_calibration.hpp"

namespace beaconloc {

struct RangeEkfParameters {
  double nis_gate = kChiSquare999OneDof;
  // The ranges a global fix is computed from: those of the last init_window_s, or the newest
  // init_min_ranges when that holds fewer (with the defaults, a single receiver ranging under 2.7
  // times a second: the CMU radios range 2-4 times a second), never older than kMaxInitWindowS.
  // Ranges the echo screen then drops leave the fix waiting for more. (Not more: a longer window's
  // dead-reckoned path, its drift not in the fix's noise, tells a mirror image from the pose by
  // chance; unit.RangeEkf.StaysInitializingUnderARowOfBeaconsWithOneReceiverAndSaysWhy.)
  static constexpr double kMaxInitWindowS = 60.0;
  // And at most this many: 5 slots a second, up to 8 receivers, the longest window is 2400; a bus
  // flooding ranges (any number within the window's span) must not make each range's work grow
  // without bound.
  static constexpr std::size_t kMaxWindowRanges = 2400;
  double init_window_s = 3.0;
  int init_min_beacons = 3;
  int init_min_ranges = 8;  // ranges (after the echo screen) a global fix needs: 3 unknowns + 5
  // A fix starts the filter when its position sigma is below the larger of
  // init_max_position_sigma_m and init_max_position_sigma_ranges times the window's typical range
  // sigma (its median): ranges with 0.5 m noise (the CMU radios) cannot give a 0.3 m fix. That
  // product stops at the largest init_max_position_sigma_m there is, whatever sigma a source
  // declares.
  double init_max_position_sigma_m = 0.3;
  double init_max_position_sigma_ranges = 2.0;
  double init_max_yaw_sigma_rad = 0.35;
  // A longer gap is not integrated (reason odometry_gap), unless a slower sensor's own period
  // allows it (OdometryTimeline).
  double max_odometry_gap_s = kDefaultMaxOdometryGapS;
  double wheel_velocity_variance_floor_m2ps2 = 1e-6;
  int reinitialize_after_gated = 15;   // 5 slots x 3 receivers refused in a row: lost
  // Ranges older than the newest odometry by more are stale.
  double max_range_age_s = static_cast<double>(kMeasurementHorizonNs) / static_cast<double>(kNsPerSecond);
  double init_retry_interval_s = 0.5;  // data time between two attempts at a global fix
  // A range of the window more than this many sigma off the global fix is dropped as an echo
  // (up to 40 % of them); 0 keeps every range.
  double init_outlier_gate_sigma = 4.0;
  // Divergence: over the last divergence_window_ranges ranges fused or gated, the pose is
  // suspect when divergence_gated_ranges of them were gated, or when the NIS of those applied
  // sums above chi-square 99.9 % for their count. A suspect pose is degraded until a global fix
  // from the window either agrees with it (the gated ranges were outliers) or contradicts it
  // (the filter is re-initialized from the fix). A good pose gates 0.1 % of good ranges
  // (nis_gate) and 3-6 % of all under 30 % echoes (the decoder refuses most): 6 of 20 then has a
  // chance of 3e-4 (at 5 %) per window, while a pose metres off meets it within 6-9 ranges.
  int divergence_window_ranges = 20;
  int divergence_gated_ranges = 6;
  // The ranging system's calibration in the state: 0 none (ranges as the decoder gives them),
  // 1 one scale and bias shared by every beacon, 2 one pair per beacon. The prior sigmas are the
  // sensor's tolerance: a scale of 1 +- range_scale_sigma, a bias of 0 +- range_bias_sigma_m.
  int range_calibration = 0;
  double range_scale_sigma = 0.1;
  double range_bias_sigma_m = 0.5;
  // The ranges' noise learnt online as k times each range's declared sigma (RangeNoiseScale:
  // the median of the innovations), instead of taken as declared: a sensor whose sigma is not
  // known, or not what its datasheet says (docs/range-noise.md).
  bool learn_range_noise = false;

  static RangeEkfParameters from(const EstimatorConfig& config);
};

class RangeEkf final : public EstimatorBase {
 public:
  explicit RangeEkf(const EstimatorConfig& config);
  std::string name() const override { return "range_ekf"; }
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<RangeEkf>(*this); }
  // Re-initializations from a global fix that contradicted a suspect pose.
  std::uint64_t divergence_reinitializations() const { return divergence_reinitializations_; }
  // range_innovation_nll_nats: the mean negative log-likelihood of the ranges' innovations so
  // far (nats per range, ranges in metres; a truncated likelihood, see innovation_nll_sum_), a
  // fit to the data that needs no ground truth: lower is better, and noise settings can be
  // chosen by it (scripts/replay-noise-fit.sh). With the calibration, the ranges' scale and bias
  // with their sigmas (range_calibration.hpp).
  std::vector<StateValue> state_values() const override;

 private:
  RangeEkf(const EstimatorConfig& config, const RangeEkfParameters& params);
  PoseBelief pose_belief() const override;
  StartupWait waiting_for() const override { return waiting_for_; }
  bool place(const Pose2& pose_map_base, const Cov3& covariance) override;
  bool suspect() const override { return suspect_; }
  struct BufferedRange {
    RangeMeasurement range;
    Pose2 odom_pose_at_range;
  };
  // The global fix from the window of ranges (covariance inflated for the shared odometry), or
  // the start-up condition it does not meet. solved: the solver ran (the costly part).
  struct WindowFix {
    bool ok = false;
    bool solved = false;
    Pose2 pose = Pose2::Zero();
    Cov3 covariance = Cov3::Identity();
    StartupWait why_not;
    std::vector<RangeObservation> observations;  // the window's ranges after the echo screen
    // With the calibration in the state: d pose / d calibration (3 x the calibration's size),
    // how the fix moves with the scales and biases its ranges were read back with.
    Eigen::MatrixXd calibration_sensitivity;
    double variance_factor = 1.0;                // the fix's cost per degree of freedom, when above 1
  };
  struct RangeOutcome {
    bool gated;
    double nis;
  };
  // odom_pose_at_range: odom_pose_at(range.stamp_ns).
  InputResult fuse(const RangeMeasurement& range, const Pose2& odom_pose_at_range);
  WindowFix window_fix() const;
  bool attempt_due(StampNs newest_range_ns) const;
  void try_initialize();
  void watch_divergence(const RangeOutcome& outcome);
  void start_from(const WindowFix& fix, StampNs stamp_ns);
  // Every beacon of the window's pair in the state, before a fix reads their ranges back.
  void calibrate_window_beacons();

  ReceiverArray receivers_;
  RangeEkfParameters params_;
  // The filter in use: on the pose alone, or on the pose and the calibration (its size grows as
  // beacons are first heard). f(filter) on the one in use.
  template <class F>
  decltype(auto) with_filter(F&& f) {
    return calibration_.enabled() ? f(calibrating_) : f(ekf_);
  }
  template <class F>
  decltype(auto) with_filter(F&& f) const {
    return calibration_.enabled() ? f(calibrating_) : f(ekf_);
  }
  // The beacon's scale and bias, put in the state at the prior when first heard; none (the range
  // as it is) beyond RangeCalibrationStates::kMaxPairs.
  RangeCalibrationIndex calibration_of(std::uint32_t beacon_id);
  // The calibration back to its prior: its values too (values), or its covariance alone.
  void calibration_to_prior(bool values);
  std::uint64_t calibration_resets_ = 0;  // a scale left [kMinScale, kMaxScale]: started again
  // The ranges' fit, without ground truth: the sum over the ranges fused or gated (while the
  // filter has a pose) of their innovation's negative log-likelihood,
  // 0.5 (nis + log S + log 2 pi), a gated one counted at the gate (a truncated likelihood: an
  // echo weighs no more than a range at the gate).
  double innovation_nll_sum_ = 0.0;
  std::uint64_t innovations_ = 0;
  RangeNoiseScale noise_scale_;  // learn_range_noise
  Ekf<3> ekf_{pose_space()};
  RangeCalibrationStates calibration_;
  Ekf<Eigen::Dynamic> calibrating_{StateSpace<Eigen::Dynamic>::with_pose({}, RangeCalibrationStates::kPoseSize)};
  Pose2 odom_pose_ = Pose2::Zero();  // dead-reckoned, odometry frame, at now_ns()
  // The newest sample the time line stands at (integrated, its anchor, or re-anchored after a gap).
  std::optional<OdometrySample> last_odometry_;
  // The dead-reckoned pose at stamp_ns: odom_pose_ moved along the newest wheel speeds over
  // stamp_ns - now_ns() (either sign, at most odometry_gap_limit_s(); odom_pose_ beyond that).
  Pose2 odom_pose_at(StampNs stamp_ns) const;
  // The newest ranges, in stamp order (RangeEkfParameters: the window's span and size).
  std::deque<BufferedRange> window_;
  int consecutive_gated_ = 0;
  std::optional<StampNs> last_init_attempt_ns_;
  StartupWait waiting_for_;          // why the last attempt at a global fix gave no pose
  std::deque<RangeOutcome> recent_;  // the last divergence_window_ranges fused or gated
  bool suspect_ = false;             // the recent ranges contradict the pose; no fix settled it yet
  std::uint64_t divergence_reinitializations_ = 0;
};

}  // namespace beaconloc
