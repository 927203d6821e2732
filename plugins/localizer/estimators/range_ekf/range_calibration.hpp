#pragma once
// The ranging system's calibration estimated online with the pose (issue 18): each range reads
// h = scale * d + bias (core/models/range_model.hpp, RangeCalibrationIndex), with one scale and
// bias for every beacon (shared: one radio's clock and cable delay) or one pair per beacon (each
// beacon's own delay and antenna), held in range_ekf's state after [x, y, yaw] and added as the
// beacons are first heard. They are constants: no process noise. Where they are not observable
// yet (the robot has not moved, every range from one distance) the prior keeps them: a scale of
// 1 +- scale_sigma and a bias of 0 +- bias_sigma_m, the sensor's datasheet tolerance, never a
// figure fitted to a recording.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc {

enum class RangeCalibrationMode { kNone = 0, kShared = 1, kPerBeacon = 2 };

class RangeCalibrationStates {
 public:
  using State = Eigen::VectorXd;
  using Covariance = Eigen::MatrixXd;
  static constexpr Eigen::Index kPoseSize = 3;
  // At most this many pairs (per beacon: 64 states beside the pose, whose covariance each
  // odometry sample and range updates in full). The ranges of a beacon beyond them are fused as
  // they are, and the beacon counted (uncalibrated_beacons).
  static constexpr std::size_t kMaxPairs = 32;
  // A scale outside this is no ranging system's: the calibration has diverged (an unobservable
  // stretch linearized at a wrong pose) and starts again from its prior.
  static constexpr double kMinScale = 0.5;
  static constexpr double kMaxScale = 2.0;
  // The largest prior sigma of a scale: 1 +- 3 sigma stays within (kMinScale, kMaxScale).
  static constexpr double kMaxScaleSigma = 0.15;

  RangeCalibrationStates(RangeCalibrationMode mode, double scale_sigma, double bias_sigma_m)
      : mode_(mode), scale_sigma_(scale_sigma), bias_sigma_m_(bias_sigma_m) {}
  bool enabled() const { return mode_ != RangeCalibrationMode::kNone; }
  RangeCalibrationMode mode() const { return mode_; }

  // Where the beacon's scale and bias sit in the state; nullopt until they are in it.
  std::optional<RangeCalibrationIndex> index(std::uint32_t beacon_id) const;
  // Appends the beacon's pair (the shared pair, once) to x and P at the prior, uncorrelated
  // with the rest; its index. nullopt when kMaxPairs are there already (the beacon counted).
  std::optional<RangeCalibrationIndex> add(std::uint32_t beacon_id, State& x, Covariance& p);
  // Whether every scale in x lies in [kMinScale, kMaxScale].
  bool plausible(const State& x) const;
  // Every pair back to its prior, uncorrelated with the pose: its values too (values), or only
  // its covariance (the values kept as the start of a new search).
  void to_prior(State& x, Covariance& p, bool values) const;
  std::size_t uncalibrated_beacons() const { return uncalibrated_.size(); }
  // A range as the beacon's calibration in x reads it back to a distance, (range - bias) / scale,
  // and its variance (the calibration's own uncertainty is not in it: it is common to every range
  // of the beacon, and a fix carries it through its sensitivity to the calibration); the range
  // itself before the beacon's pair is in the state.
  struct Corrected {
    double range_m;
    double variance_m2;
  };
  Corrected corrected(std::uint32_t beacon_id, double range_m, double variance_m2, const State& x) const;
  // Each pair's scale and bias with its sigma: range_scale, range_bias_m (shared) or
  // range_scale_b<ID>, range_bias_m_b<ID>.
  std::vector<Estimator::StateValue> values(const State& x, const Covariance& p) const;

 private:
  std::uint32_t key(std::uint32_t beacon_id) const { return mode_ == RangeCalibrationMode::kShared ? 0 : beacon_id; }
  RangeCalibrationMode mode_;
  double scale_sigma_;
  double bias_sigma_m_;
  std::map<std::uint32_t, Eigen::Index> scale_at_;  // key -> the scale's index; the bias follows it
  std::set<std::uint32_t> uncalibrated_;             // beacons heard beyond kMaxPairs
};

}  // namespace beaconloc
