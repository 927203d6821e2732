#pragma once
// Seed 003 Sec. 3.4 (eq. 10-38): the pose filter of one frame, the global one or one LRULPS's
// (Fig. 3 and 4, red blocks): the state [x, y, theta] in that frame (eq. 1-2), predicted by the
// odometry (eq. 10, 20, 34) and updated by one group's measurements (eq. 11): a range to a beacon
// (spherical, eq. 26, noise eq. 18) or the differences of a group's ranges to its first beacon's
// (hyperbolic, eq. 27, noise eq. 19). The filter is chosen per run: the EKF, the UKF (Sec. 3.4.1)
// or the H-infinity filter (Sec. 3.4.2), all the core's filters over the core's models, so the
// three share every model and differ only in their update.
//
// Deviations:
//  - eq. 10 and 20 move the state by the odometry's increments (Delta d, Delta theta) with the
//    noise Q_T of eq. 17 (sigma 0.03 m and 0.02 rad a step, Sec. 4: "heuristic", no step length
//    given). Here the odometry is integrated at its own rate (100 Hz) by the core's
//    differential-drive model with the noise the odometry reports for its wheel velocities, as
//    every estimator here does: the same motion, and a noise that belongs to the robot.
//  - the paper's ULPS emits from all of a group's beacons at once (Kasami codes); here a group's
//    beacons fire in turn (the scenario's slots). A range updates the filter at its own stamp
//    (spherical; the sequential update of one range at a time is the stacked update of eq. 11
//    when the ranges are independent, eq. 18), and a hyperbolic epoch's ranges are moved to the
//    epoch's end through the odometry before they are differenced (ranges_at_end).
#include <cstdint>
#include <variant>
#include <vector>

#include "beaconloc/core/filters/ekf.hpp"
#include "beaconloc/core/filters/h_infinity.hpp"
#include "beaconloc/core/filters/ukf.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/range_difference_model.hpp"
#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc::scan {

enum class FilterKind : std::uint8_t { kEkf, kUkf, kHInfinity };
const char* to_string(FilterKind kind);

struct FrameFilterSettings {
  FilterKind kind = FilterKind::kEkf;
  // Sec. 3.4.1: alpha "normally set to 0.001", beta = 2 for Gaussian noise, kappa in [0, 3 - L]
  // with L = 3: 0.
  UnscentedParameters unscented{1e-3, 2.0, 0.0};
  // Sec. 3.4.2's attenuation level (theta of core/filters/h_infinity.hpp, 1/m^2 and 1/rad^2 on
  // this state); not given in the paper. 0.1 keeps the bound (P^-1 - theta I > 0) while a
  // heading's variance is under 10 rad^2, that is always where a heading means anything.
  double h_infinity_theta = 0.1;
};
// A measurement whose NIS is above chi-square's 99.9 % quantile for its size is an echo (gated).

// One range of a hyperbolic epoch: the beacon in the frame, the range and the odometry's pose
// when it arrived (any odometry frame: only differences of such poses are used).
struct EpochRange {
  Eigen::Vector3d beacon_frame_m = Eigen::Vector3d::Zero();
  double range_m = 0.0;
  Pose2 odometry_pose = Pose2::Zero();
};

class FrameFilter {
 public:
  explicit FrameFilter(const FrameFilterSettings& settings);
  FilterKind kind() const { return kind_; }
  const FrameFilterSettings& settings() const { return settings_; }

  // Start from this belief (the frame's first fixes, frame_start.hpp).
  FilterOutcome start(const Pose2& pose_frame_base, const Cov3& covariance);
  Pose2 pose() const;
  Cov3 covariance() const;

  // Eq. 10 / 20 / 34 over one odometry step of dt_s (see the deviation above).
  PredictResult predict(const OdometrySample& odometry, double dt_s, double wheel_variance_floor_m2ps2);

  // Eq. 26 with eq. 18: one range from the receiver at receiver_base_m, height receiver_z_m.
  UpdateResult update_range(const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                            const Eigen::Vector3d& beacon_frame_m, double range_m, double variance_m2);

  // Eq. 27 with eq. 19: ranges[0] is the reference beacon's. Each range is first moved to the
  // newest odometry pose (end_odometry_pose) by the filter's own prediction of how much it changed
  // over the odometry's motion since it arrived (ranges_at_end). range_variance_m2 is one
  // range's: a difference's variance (eq. 19's sigma_vT^2) is twice it.
  UpdateResult update_differences(const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                                  const std::vector<EpochRange>& ranges, const Pose2& end_odometry_pose,
                                  double range_variance_m2);

 private:
  template <class Model>
  UpdateResult update(const Model& model, const typename Model::Vector& z, double nis_gate);

  FrameFilterSettings settings_;
  FilterKind kind_;
  std::variant<Ekf<3>, Ukf<3>, HInfinityFilter<3>> filter_;
};

// The range from the pose at which a range was measured to the pose at the epoch's end, as the
// filter predicts it: z + h(pose_end) - h(pose_end (+) (odometry_end (-) odometry_at_range)).
// Exact to first order in the filter's pose error times the motion (80 ms at 0.4 m/s: 3 cm, so
// a 0.1 rad heading error leaves 3 mm).
std::vector<double> ranges_at_end(const Pose2& pose_frame_end, const Eigen::Vector2d& receiver_base_m,
                                       double receiver_z_m, const std::vector<EpochRange>& ranges,
                                       const Pose2& end_odometry_pose);

}  // namespace beaconloc::scan
