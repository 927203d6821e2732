#include "ukf_lrf_estimator.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/models/stacked_model.hpp"

namespace beaconloc::ukf_lrf {
namespace {

constexpr int kPose = 3;

std::string mode_name(Mode mode) {
  switch (mode) {
    case Mode::kFusion:
      return "ukf_lrf";
    case Mode::kLaserOnly:
      return "ukf_lrf_laser_only";
    case Mode::kBeaconsOnly:
      return "ukf_lrf_beacons_only";
  }
  return "ukf_lrf";
}

bool usable_beam(float range_m, const LaserScanSample& scan) {
  return std::isfinite(range_m) && range_m > scan.range_min_m && range_m < scan.range_max_m;
}

}  // namespace

UkfLrfParameters UkfLrfParameters::from(const EstimatorConfig& c, const std::string& estimator) {
  namespace ranges = parameter_ranges;
  ParameterReader in(c, estimator);
  UkfLrfParameters p;
  // Eq. 14: alpha in (0, 1] spreads the sigma points; beta >= 0 weighs the centre point's
  // covariance (2 for a Gaussian); L + lambda = alpha^2 (L + kappa) > 0 for every augmented size
  // L >= kPose + 1 (a pose and one range) needs kappa > -(kPose + 1).
  p.unscented.alpha = in.real("ut_alpha", p.unscented.alpha, ParameterRange::above(0.0, 1.0));
  p.unscented.beta = in.real("ut_beta", p.unscented.beta, ParameterRange::closed(0.0, 10.0));
  p.unscented.kappa = in.real("ut_kappa", p.unscented.kappa, ParameterRange::above(-(kPose + 1.0), 100.0));
  // Eq. 6: variances of the velocity noise per squared velocity; 1 is a noise as large as the motion.
  for (int i = 0; i < 4; ++i) {
    p.alpha[i] = in.real("alpha" + std::to_string(i + 1), p.alpha[i], ParameterRange::closed(0.0, 1.0));
  }
  p.beacon_sigma_m = in.real("beacon_sigma_m", p.beacon_sigma_m, ParameterRange::above(0.0, 10.0));
  p.laser_sigma_m = in.real("laser_sigma_m", p.laser_sigma_m, ParameterRange::above(0.0, 10.0));
  p.initial_pose = c.initial_pose;
  p.initial_sigma_xy_m = in.real("initial_sigma_xy_m", p.initial_sigma_xy_m, ranges::kPositionSigmaM);
  p.initial_sigma_yaw_rad =
      in.real("initial_sigma_yaw_rad", p.initial_sigma_yaw_rad, ranges::kHeadingSigmaRad);
  // Where the scanner sits on the robot: within 5 m of its origin.
  const ParameterRange mount_m = ParameterRange::closed(-5.0, 5.0);
  p.laser_mount_base =
      Pose2(in.real("laser_mount_x_m", 0.0, mount_m), in.real("laser_mount_y_m", 0.0, mount_m),
            in.real("laser_mount_yaw_rad", 0.0, ParameterRange::closed(-M_PI, M_PI)));
  p.max_odometry_gap_s = in.real("max_odometry_gap_s", p.max_odometry_gap_s, ranges::kDataDurationS);
  // N_W: the augmented state grows by one per beam (a 1000-beam state is a 1000 x 1000 Cholesky a scan).
  p.max_beams = in.count("max_beams", p.max_beams, 1, 1000);
  p.max_measurement_age_s = in.real("max_measurement_age_s", p.max_measurement_age_s, ranges::kDataDurationS);
  // 0: no gate (the paper's eq. 16-21). Below 1 sigma most good beams would be refused.
  p.beam_gate_sigma = in.real("beam_gate_sigma", p.beam_gate_sigma, ParameterRange::closed(0.0, 100.0));
  in.finish();
  if (p.beam_gate_sigma > 0.0 && p.beam_gate_sigma < 1.0) {
    throw std::invalid_argument(estimator + ": beam_gate_sigma must be 0 (no gate) or in [1, 100]");
  }
  if (p.initial_pose && !p.initial_pose->allFinite()) {
    throw std::invalid_argument(estimator + ": the initial pose must be finite");
  }
  return p;
}

UkfLrf::UkfLrf(const EstimatorConfig& config, Mode mode)
    : UkfLrf(config, mode, UkfLrfParameters::from(config, mode_name(mode))) {}

UkfLrf::UkfLrf(const EstimatorConfig& config, Mode mode, const UkfLrfParameters& params)
    : EstimatorBase(params.max_odometry_gap_s),
      mode_(mode),
      params_(params),
      grid_(config.occupancy_grid),
      motion_model_(params.alpha),
      // Eq. 16: the measurement noise augmented, as the paper's sigma points spread it.
      filter_(pose_space(), UkfOptions{params.unscented, true}) {
  if (mode_ != Mode::kBeaconsOnly && !grid_) {
    throw std::invalid_argument(name() + " needs the occupancy grid of the map (localizer --map FILE)");
  }
  if (mode_ != Mode::kLaserOnly && config.receivers.size() != 1) {
    throw std::invalid_argument(name() + " takes the ranges of one receiver (seed 001 Sec. 4.1)");
  }
  if (mode_ != Mode::kLaserOnly) {
    receiver_base_m_ = config.receivers.receivers_base_m[0];
    receiver_height_m_ = config.receivers.receiver_height_m;
  }
  if (params_.initial_pose) {
    filter_.reset(*params_.initial_pose, Cov3(Eigen::Vector3d(params_.initial_sigma_xy_m * params_.initial_sigma_xy_m,
                                       params_.initial_sigma_xy_m * params_.initial_sigma_xy_m,
                                       params_.initial_sigma_yaw_rad * params_.initial_sigma_yaw_rad)
                           .asDiagonal()));
    start(0);
  }
}

std::string UkfLrf::name() const { return mode_name(mode_); }

InputResult UkfLrf::update(const RangeMeasurement& r) {
  // A range's numbers first: the same bad range gets the same reason from every estimator.
  if (InputResult numbers = check_range_numbers(r); !numbers.accepted) return numbers;
  if (mode_ == Mode::kLaserOnly) return InputResult::rejected(Rejection::kBeaconsUnused);
  if (r.receiver_id != 0) return InputResult::rejected(Rejection::kUnknownReceiver);
  if (map().size() == 0) return InputResult::rejected(Rejection::kNoBeaconMap);  // none with a map position
  // The id is not used to associate, but a beacon whose map position is not known (seed 003's
  // uncalibrated LRULPS) must not be taken for a known one it happens to be near.
  if (r.beacon_id != kBeaconUnidentified && map().find_local(r.beacon_id)) {
    return InputResult::rejected(Rejection::kUncalibratedBeacon);
  }
  if (!has_pose()) return InputResult::rejected(Rejection::kNoInitialPose);
  // Anonymous or not, the range is associated (Table 2): the id a beacon may announce is not
  // used, as in the paper (Sec. 4.1). It is fused on its own, not held until the cycle of four
  // is complete as the paper does: the robot moves 6.6 cm between two slots (0.42 m/s, 156 ms).
  return fuse_or_hold({r}, std::nullopt, r.stamp_ns);
}

InputResult UkfLrf::update_laser(const LaserScanSample& scan) {
  if (mode_ == Mode::kBeaconsOnly) return InputResult::rejected(Rejection::kLaserUnused);
  if (scan.ranges_m.empty() || !std::isfinite(scan.angle_min_rad) ||
      !std::isfinite(scan.angle_increment_rad) || scan.angle_increment_rad == 0.0f ||
      !std::isfinite(scan.range_max_m) || !(scan.range_min_m >= 0.0f) ||
      !(scan.range_max_m > scan.range_min_m)) {
    return InputResult::rejected(Rejection::kMalformedScan);
  }
  if (!has_pose()) return InputResult::rejected(Rejection::kNoInitialPose);
  ScanBeams beams = usable_beams(scan);
  if (beams.ranges_m.empty()) return InputResult::rejected(Rejection::kNoUsableBeams);
  return fuse_or_hold({}, std::move(beams), scan.stamp_ns);
}

// Sec. 4.1: the update uses whatever arrived. A measurement stamped at or before the filter's
// time (its odometry came first) is fused at once, in an iteration without the motion terms; one
// stamped later waits for the odometry step that reaches its stamp. Fusing it a step late was
// measured to bias the laser modes (RMSE 0.0088 -> 0.0120 m: 9 mm of travel per 22 ms step).
InputResult UkfLrf::fuse_or_hold(std::vector<RangeMeasurement> ranges, std::optional<ScanBeams> beams,
                                 StampNs stamp_ns) {
  const auto now = now_ns();
  if (now && stamp_ns <= *now) {
    if (static_cast<double>(*now - stamp_ns) * 1e-9 > params_.max_measurement_age_s) {
      return InputResult::rejected(beams ? Rejection::kStaleScan : Rejection::kStaleRange);
    }
    return step(std::nullopt, std::move(ranges), beams ? &*beams : nullptr);
  }
  if (beams) {
    pending_scan_ = std::move(*beams);  // a newer scan replaces one not yet fused
    pending_scan_stamp_ns_ = stamp_ns;
  } else {
    if (pending_ranges_.size() >= 64) return InputResult::rejected(Rejection::kRangesWithoutOdometry);
    pending_ranges_.push_back(ranges.front());
  }
  return InputResult::ok();
}

UkfLrf::ScanBeams UkfLrf::usable_beams(const LaserScanSample& scan) const {
  // The paper fuses N_W = 19 beams of its scanner's 761 (Sec. 3.4): a longer scan is thinned to
  // max_beams evenly spread beams; invalid readings (REP-117: out of limits, non-finite) skipped.
  ScanBeams out;
  out.beams.mount_base = params_.laser_mount_base;
  out.beams.max_range_m = scan.range_max_m;
  const std::size_t n = scan.ranges_m.size(), wanted = static_cast<std::size_t>(params_.max_beams);
  for (std::size_t k = 0; k < std::min(n, wanted); ++k) {
    const std::size_t i =
        n <= wanted ? k : (k * (n - 1) + (wanted - 1) / 2) / (wanted - 1 == 0 ? 1 : wanted - 1);
    if (!usable_beam(scan.ranges_m[i], scan)) continue;
    out.ranges_m.push_back(scan.ranges_m[i]);
    out.beams.add_beam(scan.angle_min_rad + static_cast<double>(i) * scan.angle_increment_rad);
  }
  return out;
}

InputResult UkfLrf::predict(const OdometrySample& o) {
  if (!has_pose()) {
    // The numbers first: the same bad sample gets the same reason from every estimator.
    if (InputResult numbers = check_odometry_numbers(o); !numbers.accepted) return numbers;
    return InputResult::rejected(Rejection::kNoInitialPose);
  }
  const OdometryTimeline::Step t = advance(o);
  if (!t.result.accepted) return t.result;
  if (!t.integrate) return InputResult::ok();
  // The measurements held for this step: those stamped up to now.
  std::vector<RangeMeasurement> due;
  for (auto it = pending_ranges_.begin(); it != pending_ranges_.end();) {
    if (it->stamp_ns <= o.stamp_ns) {
      due.push_back(*it);
      it = pending_ranges_.erase(it);
    } else {
      ++it;
    }
  }
  std::optional<ScanBeams> scan;
  if (pending_scan_ && pending_scan_stamp_ns_ <= o.stamp_ns) {
    scan = std::move(pending_scan_);
    pending_scan_.reset();
  }
  const Motion motion{(o.wheel_velocity_right_mps + o.wheel_velocity_left_mps) / 2.0,
                      (o.wheel_velocity_right_mps - o.wheel_velocity_left_mps) / o.wheel_base_m, t.dt_s};
  const InputResult result = step(motion, std::move(due), scan ? &*scan : nullptr);
  if (!result.accepted && !last_step_predicted_) return result;  // nothing applied: the odometry's fault
  if (!result.accepted) deferred_rejections_.push_back(*result.rejection);  // predicted; the correction failed
  return InputResult::ok();
}

std::vector<Rejection> UkfLrf::take_deferred_rejections() {
  std::vector<Rejection> out;
  out.swap(deferred_rejections_);
  return out;
}

InputResult UkfLrf::step(std::optional<Motion> motion, std::vector<RangeMeasurement> ranges,
                         const ScanBeams* scan) {
  last_step_predicted_ = false;
  const int n_b = static_cast<int>(ranges.size()), n_w = scan ? static_cast<int>(scan->ranges_m.size()) : 0;
  if (!motion && n_b + n_w == 0) return InputResult::ok();

  // Eq. 16: h is the beacon ranges (each to the beacon Table 2 associates it with), then the
  // beams; eq. 7 their noise, augmented (variances: ERRATA, the paper's diagonal writes sigma
  // where sigma^2 is meant). The association needs the sigma points, which need R first.
  const double beacon_variance_m2 = params_.beacon_sigma_m * params_.beacon_sigma_m;
  const double laser_variance_m2 = params_.laser_sigma_m * params_.laser_sigma_m;
  Eigen::VectorXd r_diagonal(n_b + n_w);
  r_diagonal.head(n_b).setConstant(beacon_variance_m2);
  r_diagonal.tail(n_w).setConstant(laser_variance_m2);
  Eigen::MatrixXd r = r_diagonal.asDiagonal();

  // Eq. 1-14: one set of sigma points over [x; n_u; n_B; n_W], moved by the motion (eq. 9-11),
  // the prior kept whatever the correction does.
  std::optional<SigmaPoints<3>> points;
  if (motion) {
    Ukf<3>::Predicted predicted =
        filter_.predict(motion_model_, Eigen::Vector2d(motion->v_mps, motion->omega_radps), motion->dt_s, std::move(r));
    if (!predicted.result.applied()) return InputResult::of(predicted.result.outcome);
    last_step_predicted_ = true;
    points = std::move(predicted.points);
  } else {
    points = filter_.sigma_points(std::move(r));
  }
  if (n_b + n_w == 0) return InputResult::ok();
  if (!points) return InputResult::rejected(Rejection::kCovarianceNotPositiveDefinite);

  const std::optional<std::vector<std::uint32_t>> associated = associate(ranges, *points);
  if (!associated) return InputResult::rejected(Rejection::kNoBeaconToAssociate);
  ModelList<RangeModel> beacon_ranges;
  for (const std::uint32_t id : *associated) {
    beacon_ranges.add(
        RangeModel(receiver_base_m_, receiver_height_m_, map().find(id)->position_map_m, beacon_variance_m2));
  }
  const StackedModel<ModelList<RangeModel>, LaserBeamModel> model(
      std::move(beacon_ranges), LaserBeamModel(grid_, scan ? scan->beams : LaserBeams{}, laser_variance_m2));
  Eigen::VectorXd z(n_b + n_w);
  for (int k = 0; k < n_b; ++k) z(k) = ranges[k].range_m;
  for (int k = 0; k < n_w; ++k) z(n_b + k) = scan->ranges_m[k];
  // Eq. 15-22, the beams that are gross outliers on their own left out (beam_gate_sigma).
  const UpdateResult corrected_by = filter_.update(
      *points, model, z, std::numeric_limits<double>::infinity(),
      ComponentGate{n_b, n_w, params_.beam_gate_sigma});  // 0: no gate (the paper)
  // Counted when they were left out: of an update applied, or one that had nothing else to fuse.
  if (corrected_by.applied() || corrected_by.outcome == FilterOutcome::kEveryComponentGated) {
    beams_gated_ += static_cast<std::uint64_t>(corrected_by.components_gated);
  }
  if (!corrected_by.applied()) return InputResult::of(corrected_by.outcome);
  corrected(*now_ns());
  for (int k = 0; k < n_b; ++k) {
    // For evaluation against a simulator's truth; bounded, as no one may ever ask.
    if (associations_.size() >= 4096) associations_.erase(associations_.begin());
    associations_.push_back({ranges[k].stamp_ns, ranges[k].receiver_id, (*associated)[k]});
  }
  return InputResult::ok();
}

std::optional<std::vector<std::uint32_t>> UkfLrf::associate(const std::vector<RangeMeasurement>& ranges,
                                                            const SigmaPoints<3>& points) const {
  if (ranges.empty()) return std::vector<std::uint32_t>{};
  // Lines 1-5: the predicted range to every beacon over the sigma points, its mean and variance.
  const Eigen::MatrixXd& states = points.states();
  const UnscentedWeights& w = points.weights();
  const Eigen::Index count = states.cols();
  std::vector<PredictedBeaconRange> predicted;
  predicted.reserve(map().size());
  map().for_each([&](const Beacon& b) {
    Eigen::VectorXd z(count);
    for (Eigen::Index i = 0; i < count; ++i) {
      z(i) = i > 0 && states.col(i) == states.col(0)
                 ? z(0)
                 : predict_range(Pose2(states.col(i)), receiver_base_m_, receiver_height_m_, b.position_map_m).range_m;
    }
    const double mean_z = z.dot(w.mean);  // line 3
    const Eigen::RowVectorXd centred = (z.array() - mean_z).matrix().transpose();
    const double var_z = (centred * w.covariance.asDiagonal() * centred.transpose())(0, 0) +
                         params_.beacon_sigma_m * params_.beacon_sigma_m;  // line 4, with its noise (line 2)
    predicted.push_back({b.id, mean_z, var_z});
  });
  std::vector<std::uint32_t> out;
  for (const RangeMeasurement& r : ranges) {
    const auto j = most_likely_beacon(r.range_m, predicted);  // lines 6-11
    if (!j) return std::nullopt;
    out.push_back(*j);
  }
  return out;
}

EstimatorBase::PoseBelief UkfLrf::pose_belief() const {
  PoseBelief belief{filter_.state(), filter_.covariance()};
  if (grid_ && mode_ != Mode::kBeaconsOnly) {
    const double r = grid_->resolution_m();
    belief.covariance.topLeftCorner<2, 2>() += (r * r / 12.0) * Eigen::Matrix2d::Identity();
  }
  return belief;
}

std::vector<Estimator::StateValue> UkfLrf::state_values() const {
  return {{"beams_gated", static_cast<double>(beams_gated_), 0.0}};
}

std::vector<Estimator::Association> UkfLrf::take_associations() {
  std::vector<Association> out;
  out.swap(associations_);
  return out;
}

bool UkfLrf::place(const Pose2& pose, const Cov3& covariance) {
  // Placed by hand again (Sec. 4.1): a pose the base checked.
  return filter_.reset(pose, covariance) == FilterOutcome::kApplied;
}

namespace {
BEACONLOC_REGISTER_ESTIMATOR("ukf_lrf", "seed 001 UKF: anonymous beacon ranges and laser scans fused",
                             "seed001_classroom.yaml",
                             [](const EstimatorConfig& c) {
                               return std::make_unique<UkfLrf>(c, Mode::kFusion);
                             });
BEACONLOC_REGISTER_ESTIMATOR("ukf_lrf_laser_only", "seed 001 UKF on laser scans alone (the paper's case 5)",
                             "seed001_classroom.yaml",
                             [](const EstimatorConfig& c) {
                               return std::make_unique<UkfLrf>(c, Mode::kLaserOnly);
                             });
BEACONLOC_REGISTER_ESTIMATOR("ukf_lrf_beacons_only",
                             "seed 001 UKF on anonymous beacon ranges alone (the paper's case 4)",
                             "seed001_classroom.yaml",
                             [](const EstimatorConfig& c) {
                               return std::make_unique<UkfLrf>(c, Mode::kBeaconsOnly);
                             });
}  // namespace

}  // namespace beaconloc::ukf_lrf
