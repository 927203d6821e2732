#pragma once
// The DUHL estimator of seed 000 (Kim & Kim 2013): an EKF on [x, y, phi] predicted by odometry
// (eq. 14, 16) and corrected with the pose the UHL computes (eq. 15, 17-21) from the dynamic
// distance estimates of every available Tx at the same instant (Section IV: eq. 23-32).
// Also `uhl_last2`, the paper's comparison: UHL on the measured distances of the last two Txs.
#include <map>
#include <optional>

#include "beaconloc/core/chi_square.hpp"
#include "beaconloc/core/estimator_base.hpp"
#include "beaconloc/core/filters/ekf.hpp"
#include "distance_prediction.hpp"
#include "uhl.hpp"

namespace beaconloc::duhl {

// The UHL needs the distances of at least two Txs (Sec. II-B).
inline constexpr std::size_t kMinTxs = 2;

struct DuhlParameters {
  UhlOptions uhl;
  // Eq. 31-32: a Tx whose largest distance variance exceeds this is discarded. The paper sets it
  // experimentally without printing it; (3 cm)^2 is our choice, three times sigma_dd.
  double discard_variance_m2 = 0.03 * 0.03;
  double observation_nis_gate = kChiSquare999ThreeDof;
  // UHL poses refused in a row (2 s at 5 Hz) before the filter restarts from the UHL; 0: never.
  // Not in the paper: a robot that lost track must find it again. Measured with
  // `beaconloc accuracy` on trajectory 4, seeds 1-20: without it seed 19 stayed lost (E_p RMS
  // 0.191 m); with it that seed ends at 0.094 m, the other 19 unchanged.
  int reinitialize_after_gated = 10;
  double max_odometry_gap_s = kDefaultMaxOdometryGapS;
  double wheel_velocity_variance_floor_m2ps2 = 1e-6;
  // Before the first pose, a new Tx's unmeasured receivers start from the measured one with
  // this standard deviation (the receivers are 0.33 m apart).
  double unmeasured_sigma_m = 0.4;
  // R of eq. 21: false (default) counts only what the distance measurements put into Q^i, once
  // over the corrections that reuse it (see Duhl::observation_covariance); true takes eq. 21 as
  // printed, with the full Q^i of eq. 24. Measured on the seed 000 scenarios: NEES in the 95 %
  // band for 83-90 % of steps (default) against 39-48 % (as printed).
  bool observation_covariance_as_printed = false;
  // A measured distance whose squared innovation against its prediction q_l exceeds this many
  // variances (chi-square, 1 dof, 99.9 %) discards the Tx's estimate, which is then initialized
  // anew from the pose (eq. 28-29) and corrected with the measurement; 0: never. Not in the paper.
  double distance_innovation_gate = kChiSquare999OneDof;
  // Echoes (not in the paper, whose ranges are all direct): once there is a pose, a measured
  // distance whose squared innovation against the distance the pose predicts (eq. 28, its
  // variance eq. 29 plus the measurement's) exceeds this many variances is refused as gated;
  // 0: never. 25: 5 sigma, wider than chi-square's 99.9 % (10.83), which refused direct
  // distances in turns (docs/accuracy-seed000.md, departure 4). An echo's extra path (0.3 m and
  // more) is many sigmas.
  double range_pose_gate = 25.0;
  // Distances refused by range_pose_gate in a row before the pose is suspect (published
  // degraded: two firings' worth), and before it is dropped and found again from the beacons, as
  // at the start (15: a second of ranges from three receivers at 5 Hz).
  int suspect_after_gated_ranges = 6;
  int lost_after_gated_ranges = 15;
  // Before a UHL pose is used to start (or restart) the filter, every Tx's distances must be
  // within this many sigmas of the distances the pose predicts; otherwise the Tx without which
  // the others agree is dropped, or, when there is none, every Tx (the next firings measure
  // them again), and the start waits.
  double start_residual_gate_sigma = kDefaultResidualGateSigma;

  static DuhlParameters from(const EstimatorConfig& config);
};

class Duhl final : public EstimatorBase {
 public:
  explicit Duhl(const EstimatorConfig& config);
  std::string name() const override { return "duhl"; }
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<Duhl>(*this); }
  std::size_t available_txs() const { return available_.size(); }
  // Tx estimates discarded because their own measurement contradicted them (distance_innovation_gate).
  std::uint64_t contradicted_txs() const { return contradicted_txs_; }
  // Tx estimates dropped because a start's UHL pose could not explain them (echoes).
  std::uint64_t refused_start_txs() const { return refused_start_txs_; }
  std::vector<StateValue> state_values() const override;

 private:
  Duhl(const EstimatorConfig& config, const DuhlParameters& params);
  PoseBelief pose_belief() const override { return {ekf_.state(), ekf_.covariance()}; }
  StartupWait waiting_for() const override;
  bool place(const Pose2& pose_map_base, const Cov3& covariance) override;
  bool suspect() const override { return consecutive_ranges_gated_ >= params_.suspect_after_gated_ranges; }
  struct TxEstimate {
    // q^i and Q^i (eq. 23-24, 25-27): the belief of this Tx's own Kalman filter, which the
    // range updates correct in place.
    Ekf<3> distances;
    const Distances& q() const { return distances.state(); }
    const DistanceCov& covariance() const { return distances.covariance(); }
    // The part of Q^i the distance measurements put there (eq. 27's R^q per measured receiver,
    // carried by J_g,q), without the odometry noise of eq. 24 (see observation_covariance).
    DistanceCov measurement_covariance;
  };
  void observe();
  // q^i and Q^i of a Tx not in T_A (eq. 28-30); nullopt (with the filter's outcome) when they
  // are not finite.
  std::optional<TxEstimate> new_tx_estimate(const RangeMeasurement& range, FilterOutcome& outcome) const;
  // The UHL pose of the Txs of T_A but left_out (eq. 4-13), its R (eq. 21) and whether it
  // explains every one of those Txs' distances (explains_distances).
  struct UhlFix {
    UhlSolution z;
    Cov3 r = Cov3::Identity();
    bool explains = false;
  };
  UhlFix solve(std::optional<std::uint32_t> left_out) const;
  // At a (re)start: the fix of every Tx, or of all but the one an echo spoiled (the others'
  // fix explains their distances); nullopt, with the Txs forgotten, when neither is found.
  std::optional<UhlFix> start_fix(UhlFix all);
  void lose_track();

  ReceiverRing ring_;
  DuhlParameters params_;
  Ekf<3> ekf_{pose_space()};
  std::map<std::uint32_t, TxEstimate> available_;  // T_A and Q (eq. 30)
  bool pending_observation_ = false;
  int consecutive_gated_ = 0;
  int consecutive_ranges_gated_ = 0;
  std::uint64_t contradicted_txs_ = 0;
  std::uint64_t refused_start_txs_ = 0;
  std::string uhl_failure_;  // why the last UHL solve failed
};

// The paper's baseline: UHL on the distances last measured from the last two Txs, no odometry.
// Not in the paper: a firing whose distances are impossible for the ring (possible_distances,
// an echo) is passed over, the range that completes it refused as echo_of_firing.
class UhlLast2 final : public EstimatorBase {
 public:
  explicit UhlLast2(const EstimatorConfig& config);
  std::string name() const override { return "uhl_last2"; }
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<UhlLast2>(*this); }

 private:
  PoseBelief pose_belief() const override { return last_; }
  StartupWait waiting_for() const override;
  static UhlOptions options_from(const EstimatorConfig& config);
  struct Firing {
    std::uint32_t beacon_id;
    Distances d;
    std::array<bool, 3> heard{false, false, false};
    double variance_m2 = 1e-4;
    bool impossible = false;  // its distances break the triangle inequality: an echo among them
  };
  ReceiverRing ring_;
  UhlOptions uhl_;
  std::vector<Firing> firings_;  // the latest firing of each of the last Txs heard, newest last
  bool pending_ = false;
  PoseBelief last_{Pose2::Zero(), Cov3::Identity()};  // the last UHL pose, held until the next
  std::size_t heard_by_all_ = 0;  // of the last Txs, those heard by all three receivers (at most kMinTxs)
  std::string uhl_failure_;       // why the last UHL solve failed
};

// R of eq. 21: sum over the Txs of J_z,q^i Q^i J_z,q^i^T, J_z,q^i the UHL's Jacobian at the
// solution z (the paper propagates through a first-order Taylor expansion of the same map).
Cov3 uhl_observation_covariance(const std::vector<TxDistances>& txs, const UhlSolution& z,
                                const std::vector<DistanceCov>& covariances, const UhlOptions& options);

}  // namespace beaconloc::duhl
