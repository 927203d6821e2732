// An estimator built out of tree against the installed beaconloc SDK (docs/deployment.md): an EKF on
// the pose [x, y, yaw] placed by hand (--initial-pose; `beaconloc run` gives the scenario's start),
// predicted by the wheel odometry and corrected by each identified range. It is seed 000's range
// EKF (Kim & Kim 2013: the differential-drive prediction of eq. 14 and 16, the range update of
// eq. 17-18) without its global fix from the ranges, kept small to show what a plugin holds: its
// maths on the SDK's filters and models, its parameters, its registration, and
// BEACONLOC_ESTIMATOR_PLUGIN() once.
#include <memory>
#include <string>

#include "beaconloc/core/estimator_base.hpp"
#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_plugin.hpp"
#include "beaconloc/core/filters/ekf.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/range_model.hpp"

namespace example {

using namespace beaconloc;

constexpr const char* kName = "example_placed_ekf";

struct Parameters {
  double nis_gate = 9.0;             // a range farther than 3 sigma from its prediction is gated
  double initial_sigma_xy_m = 0.05;  // how well the robot was placed
  double initial_sigma_yaw_rad = 0.05;
  double max_odometry_gap_s = 0.5;  // a longer gap in the odometry is not integrated

  static Parameters from(const EstimatorConfig& config) {
    namespace ranges = parameter_ranges;
    ParameterReader in(config, kName);
    Parameters p;
    p.nis_gate = in.real("nis_gate", p.nis_gate, ranges::kChiSquareGate);
    p.initial_sigma_xy_m = in.real("initial_sigma_xy_m", p.initial_sigma_xy_m, ranges::kPositionSigmaM);
    p.initial_sigma_yaw_rad =
        in.real("initial_sigma_yaw_rad", p.initial_sigma_yaw_rad, ranges::kHeadingSigmaRad);
    p.max_odometry_gap_s = in.real("max_odometry_gap_s", p.max_odometry_gap_s, ranges::kDataDurationS);
    in.finish();  // an unknown name is refused, listing these
    return p;
  }
};

class PlacedRangeEkf final : public EstimatorBase {
 public:
  explicit PlacedRangeEkf(const EstimatorConfig& config) : PlacedRangeEkf(config, Parameters::from(config)) {}

  std::string name() const override { return kName; }
  bool localizes_from_beacons() const override { return false; }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<PlacedRangeEkf>(*this); }

  InputResult predict(const OdometrySample& o) override {
    const OdometryTimeline::Step step = advance(o);  // gaps, duplicates, out-of-order samples refused
    if (!step.integrate || !has_pose()) return step.result;
    // Eq. 14, 16: the pose moved by the wheels, P = F P F^T + G U G^T with U the wheel speeds' noise.
    const DiffDriveMotion motion(o.wheel_base_m, o.wheel_velocity_covariance);
    const PredictResult predicted = filter_.predict(
        motion, Eigen::Vector2d(o.wheel_velocity_right_mps, o.wheel_velocity_left_mps), step.dt_s);
    return predicted.applied() ? step.result : InputResult::of(predicted.outcome);
  }

  InputResult update(const RangeMeasurement& r) override {
    // The checks every estimator makes first (a known beacon, a receiver the robot has, finite).
    if (const InputResult checked = check_range(r, map(), receivers_.size()); !checked.accepted)
      return checked;
    if (!has_pose()) return InputResult::rejected(Rejection::kNoInitialPose);
    // Eq. 17-18: h = |beacon - receiver(pose)|, its Jacobian from the model, a Joseph-form update.
    const RangeModel model(receivers_.receivers_base_m[r.receiver_id], receivers_.receiver_height_m,
                           map().find(r.beacon_id)->position_map_m, r.variance_m2);
    const UpdateResult result = filter_.update(model, RangeModel::Vector(r.range_m), params_.nis_gate);
    if (result.outcome == FilterOutcome::kApplied) corrected(r.stamp_ns);
    return InputResult::of(result.outcome);
  }

 private:
  PlacedRangeEkf(const EstimatorConfig& config, const Parameters& params)
      : EstimatorBase(params.max_odometry_gap_s),
        receivers_(config.receivers),
        params_(params),
        filter_(StateSpace<3>::with_pose()) {
    if (config.initial_pose) {
      const double xy = params_.initial_sigma_xy_m * params_.initial_sigma_xy_m;
      const double yaw = params_.initial_sigma_yaw_rad * params_.initial_sigma_yaw_rad;
      if (place(*config.initial_pose, Cov3(Eigen::Vector3d(xy, xy, yaw).asDiagonal()))) start(0);
    }
  }

  PoseBelief pose_belief() const override { return {filter_.state(), filter_.covariance()}; }
  StartupWait waiting_for() const override { return {StartupCondition::kNeedsInitialPose, 0.0, 0.0, {}}; }
  bool place(const Pose2& pose_map_base, const Cov3& covariance) override {
    return filter_.reset(pose_map_base, covariance) == FilterOutcome::kApplied;
  }

  ReceiverArray receivers_;
  Parameters params_;
  Ekf<3> filter_;
};

BEACONLOC_REGISTER_ESTIMATOR(kName, "example plugin: an EKF placed by hand, odometry and identified ranges",
                             "default.yaml",
                             [](const EstimatorConfig& c) { return std::make_unique<PlacedRangeEkf>(c); });

}  // namespace example

BEACONLOC_ESTIMATOR_PLUGIN();
