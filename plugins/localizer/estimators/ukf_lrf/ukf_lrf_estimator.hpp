#pragma once
// The UKF of seed 001 (Sensors 2015, "Sensor fusion of anonymous ultrasonic beacon ranges and
// laser scans"): the pose [x, y, theta] augmented with the noise of the two odometry velocities
// and one noise per range of the update (eq. 1-8), the scaled unscented transform (eq. 2, 12-14;
// alpha = 0.6, kappa = 0, beta = 2 of eq. 23), the velocity motion model (eq. 9-11) with the
// noise of eq. 6, anonymous beacon ranges associated by maximum likelihood (Table 2), laser
// ranges by ray casting on the occupancy grid, and the correction of eq. 15-22 with whatever
// measurements arrived since the last step (Sec. 4.1: asynchronous, the missing terms dropped).
//
// Modes (registered names): ukf_lrf (fusion), ukf_lrf_laser_only, ukf_lrf_beacons_only.
#include <array>
#include <optional>
#include <vector>

#include "beacon_association.hpp"
#include "beaconloc/core/estimator_base.hpp"
#include "beaconloc/core/filters/ukf.hpp"
#include "beaconloc/core/models/laser_beam_model.hpp"
#include "beaconloc/core/models/velocity_motion.hpp"

namespace beaconloc::ukf_lrf {

enum class Mode { kFusion, kLaserOnly, kBeaconsOnly };

struct UkfLrfParameters {
  UnscentedParameters unscented;                        // eq. 23
  std::array<double, 4> alpha{0.02, 0.02, 0.02, 0.02};  // eq. 6, Table 3 case 3
  double beacon_sigma_m = 0.4;                          // sigma_nB, Table 3 case 3
  double laser_sigma_m = 0.1;                           // sigma_nW, Table 3 case 3
  // The paper places the robot at its initial pose by hand (Sec. 4.1): no estimate without
  // EstimatorConfig::initial_pose (localizer --initial-pose).
  std::optional<Pose2> initial_pose;
  double initial_sigma_xy_m = 0.05;
  double initial_sigma_yaw_rad = 0.05;
  Pose2 laser_mount_base = Pose2::Zero();
  double max_odometry_gap_s = kDefaultMaxOdometryGapS;
  int max_beams = 19;                  // N_W of Sec. 3.4: longer scans are thinned evenly
  double max_measurement_age_s = 0.1;  // a range or scan older than this behind the filter is stale
  // Departure from eq. 16-21 (which fuse every beam): a beam whose reading is more than this many
  // of its own predicted standard deviations from the ray cast (|z_i - z_i_mean| > g sqrt(S_ii),
  // eq. 18-19) is left out of the update (ComponentGate), counted in `beams_gated`. In a room
  // the map does not fully know (people, furniture moved in), such beams met something the map
  // lacks; fused, a few of them pull the pose off the corridor. 0: no gate, every beam fused as
  // the paper does.
  double beam_gate_sigma = 3.0;

  // estimator: the mode's registered name, for the messages.
  static UkfLrfParameters from(const EstimatorConfig& config, const std::string& estimator);
};

class UkfLrf final : public EstimatorBase {
 public:
  UkfLrf(const EstimatorConfig& config, Mode mode);
  std::string name() const override;
  // Placed by hand (seed 001 Sec. 4.1): anonymous ranges cannot give a first pose.
  bool localizes_from_beacons() const override { return false; }
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  bool uses_laser() const override { return mode_ != Mode::kBeaconsOnly; }
  InputResult update_laser(const LaserScanSample& scan) override;
  std::vector<Association> take_associations() override;
  std::vector<Rejection> take_deferred_rejections() override;
  std::vector<StateValue> state_values() const override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<UkfLrf>(*this); }

 private:
  UkfLrf(const EstimatorConfig& config, Mode mode, const UkfLrfParameters& params);
  // The filter's belief, its position covariance given the map's own error where the laser
  // places the robot: the grid cannot place a face better than within its cell, an error every
  // beam and every scan share, which the filter (eq. 7: each beam's noise its own) does not hold
  // (a uniform error over a cell, r^2 / 12 per axis).
  PoseBelief pose_belief() const override;
  // Placed by hand (Sec. 4.1): until then it waits for that, whatever else it has.
  StartupWait waiting_for() const override { return {StartupCondition::kNeedsInitialPose, 0.0, 0.0, {}}; }
  bool needs_beacon_map() const override { return false; }
  bool place(const Pose2& pose_map_base, const Cov3& covariance) override;
  struct Motion {
    double v_mps, omega_radps, dt_s;
  };
  struct ScanBeams {
    LaserBeams beams;
    std::vector<double> ranges_m;
  };
  // Table 2: the most likely beacon of each range over the sigma points; nullopt when a range
  // has none.
  std::optional<std::vector<std::uint32_t>> associate(const std::vector<RangeMeasurement>& ranges,
                                                      const SigmaPoints<3>& points) const;
  // One iteration of Table 1: one set of sigma points of the augmented state, the motion of
  // eq. 9-11 (when there is one) and the correction with the measurements given (the missing
  // terms dropped).
  InputResult step(std::optional<Motion> motion, std::vector<RangeMeasurement> ranges, const ScanBeams* scan);
  InputResult fuse_or_hold(std::vector<RangeMeasurement> ranges, std::optional<ScanBeams> beams,
                           StampNs stamp_ns);
  ScanBeams usable_beams(const LaserScanSample& scan) const;

  Mode mode_;
  UkfLrfParameters params_;
  std::shared_ptr<const OccupancyGrid> grid_;
  Eigen::Vector2d receiver_base_m_ = Eigen::Vector2d::Zero();
  double receiver_height_m_ = 0.0;
  VelocityMotion motion_model_;  // eq. 6, 9-11
  Ukf<3> filter_;                // eq. 1-5, 12-22 on [x, y, theta]
  std::vector<RangeMeasurement> pending_ranges_;  // stamped after the filter's time
  std::optional<ScanBeams> pending_scan_;
  StampNs pending_scan_stamp_ns_ = 0;
  bool last_step_predicted_ = false;
  std::uint64_t beams_gated_ = 0;  // UkfLrfParameters::beam_gate_sigma
  std::vector<Association> associations_;
  std::vector<Rejection> deferred_rejections_;
};

}  // namespace beaconloc::ukf_lrf
