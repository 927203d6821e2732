#pragma once
// two_receiver_ekf: seed 004's self-localization. The robot carries two receivers, front and
// rear; each is tracked by its own EKF on its planar position (eq. 3: moved by the wheel odometry;
// eq. 4-1: updated by each range to a ceiling generator at a known position, eq. 5-10), and the
// robot's pose is taken from the pair (eq. 11) with the covariance eq. 12 gives
// (receiver_pair.hpp). Placed by hand, as in the paper's experiment (Sec. 4: "the initial value
// of the posture estimation are set arbitrary"). Not in the paper (its ranges are direct): of the
// two receivers' ranges to one firing, one longer than the receivers' separation allows is
// refused as an echo (ranges_of_one_firing_agree), and until a receiver's gate closes a range
// much longer than predicted is down-weighted (open_gate_echo_sigma).
#include <array>
#include <optional>

#include "beaconloc/core/chi_square.hpp"
#include "beaconloc/core/estimator_base.hpp"
#include "beaconloc/core/filters/ekf.hpp"
#include "receiver_pair.hpp"

namespace beaconloc {

struct TwoReceiverEkfParameters {
  // Seed 004 Sec. 4 sets Q = [100, 100] and G = 1.80 "intentionally to give the more confidence
  // to the measurements", in units the copy does not give. Here G is each range's own variance
  // (the decoder's) and Q is the odometry's modelled noise carried to each receiver
  // (receiver_step) plus this floor per second of driving, so that a receiver's belief never
  // claims more than the odometry can hold.
  double process_noise_m2ps = 1e-4;
  // The initial pose's standard deviations: the paper starts 0.7 m from the truth.
  double initial_sigma_m = 1.0;
  double initial_sigma_rad = 0.5;
  // A receiver's ranges are gated (NIS, chi-square 1 dof) only once its filter has settled: its
  // last gate_after_agreeing ranges all within the gate. Before that the start is a guess and the
  // linearized covariance shrinks faster than the error does, so that a gate would refuse the very
  // ranges that must pull the estimate in (from 0.7 m off, ranges were gated within the first
  // second). The same number of ranges gated in a row opens the gate again: a filter that no
  // longer agrees with any range must be able to come back.
  double nis_gate = kChiSquare999OneDof;
  int gate_after_agreeing = 10;
  // Not in the paper (its ranges are direct): while a receiver's gate is open, a range longer
  // than predicted by more than open_gate_echo_sigma sigma of its innovation is fused with its
  // variance grown until it is at that many sigma (its weight falls as 1 / innovation^2). An echo
  // is only ever longer, and from a start 0.7 m off an echo among the first ranges pulled a
  // receiver a metre away (seed 3, 30 % echoes: 1.23 m at 0.4 s); a shorter range pulls at full
  // weight, so a start that is off still converges (from 0.44 s to 0.52 s, median, selective
  // activation). 0: every range at its own variance.
  double open_gate_echo_sigma = 1.0;
  // The two receivers' estimates are suspect (the pose degraded) while their distance differs
  // from the mounting's separation by more than this many sigma.
  double separation_gate_sigma = 4.0;
  double max_odometry_gap_s = kDefaultMaxOdometryGapS;
  double wheel_velocity_variance_floor_m2ps2 = 1e-6;

  static TwoReceiverEkfParameters from(const EstimatorConfig& config);
};

class TwoReceiverEkf final : public EstimatorBase {
 public:
  explicit TwoReceiverEkf(const EstimatorConfig& config);
  std::string name() const override { return "two_receiver_ekf"; }
  bool localizes_from_beacons() const override { return false; }
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<TwoReceiverEkf>(*this); }

 private:
  static constexpr std::size_t kFront = 0;
  static constexpr std::size_t kRear = 1;
  PoseBelief pose_belief() const override;
  StartupWait waiting_for() const override { return {StartupCondition::kNeedsInitialPose, 0.0, 0.0, {}}; }
  bool place(const Pose2& pose_map_base, const Cov3& covariance) override;
  bool suspect() const override;
  PairPose pair_pose() const;

  ReceiverPair pair_;
  double receiver_z_m_;
  TwoReceiverEkfParameters params_;
  std::array<Ekf<2>, 2> receivers_{Ekf<2>(StateSpace<2>()), Ekf<2>(StateSpace<2>())};  // [front, rear]: each receiver's planar position
  // Per receiver: ranges in a row within the gate (agreeing) or refused by it (gated), and
  // whether its gate is closed (gate_after_agreeing).
  struct GateState {
    int agreeing = 0;
    int gated = 0;
    bool closed = false;
  };
  std::array<GateState, 2> gates_{};
  // Each receiver's last range, to tell an echo by the other receiver's range of the same firing
  // (not in the paper: its ranges are all direct).
  std::array<std::optional<RangeMeasurement>, 2> last_heard_{};
};

}  // namespace beaconloc
