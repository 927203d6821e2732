#include "ukf_lrf_estimator.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <stdexcept>

#include "beaconloc/core/estimator_parameters.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/filters/symmetric.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/models/velocity_motion.hpp"

namespace beaconloc::ukf_lrf {
namespace {

constexpr int kPose = 3;
constexpr int kMotionNoise = 2;  // eq. 8: n_u on (v, omega)

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
  in.finish();
  if (p.initial_pose && !p.initial_pose->allFinite()) {
    throw std::invalid_argument(estimator + ": the initial pose must be finite");
  }
  return p;
}

UkfLrf::UkfLrf(const EstimatorConfig& config, Mode mode)
    : UkfLrf(config, mode, UkfLrfParameters::from(config, mode_name(mode))) {}

UkfLrf::UkfLrf(const EstimatorConfig& config, Mode mode, const UkfLrfParameters& params)
    : EstimatorBase(params.max_odometry_gap_s), mode_(mode), params_(params), grid_(config.occupancy_grid) {
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
    mean_ = *params_.initial_pose;
    covariance_ = Cov3(Eigen::Vector3d(params_.initial_sigma_xy_m * params_.initial_sigma_xy_m,
                                       params_.initial_sigma_xy_m * params_.initial_sigma_xy_m,
                                       params_.initial_sigma_yaw_rad * params_.initial_sigma_yaw_rad)
                           .asDiagonal());
    start(0);
  }
}

std::string UkfLrf::name() const { return mode_name(mode_); }

InputResult UkfLrf::update(const RangeMeasurement& r) {
  // A range's numbers first: the same bad range gets the same reason from every estimator.
  if (InputResult numbers = check_range_numbers(r); !numbers.accepted) return numbers;
  if (mode_ == Mode::kLaserOnly) return InputResult::rejected(Rejection::kBeaconsUnused);
  if (r.receiver_id != 0) return InputResult::rejected(Rejection::kUnknownReceiver);
  if (map().empty()) return InputResult::rejected(Rejection::kNoBeaconMap);
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
  const int n_u = motion ? kMotionNoise : 0;
  const int n_b = static_cast<int>(ranges.size()), n_w = scan ? static_cast<int>(scan->ranges_m.size()) : 0;
  if (!motion && n_b + n_w == 0) return InputResult::ok();

  // Eq. 1-5, 7: augmented mean (noises zero-mean, eq. 4) and block-diagonal covariance.
  const Eigen::Index l = kPose + n_u + n_b + n_w;
  Eigen::VectorXd mean_a = Eigen::VectorXd::Zero(l);
  mean_a.head<3>() = mean_;
  Eigen::MatrixXd cov_a = Eigen::MatrixXd::Zero(l, l);
  cov_a.topLeftCorner<3, 3>() = covariance_;
  if (motion) {
    // Eq. 6, floored so that a robot at rest keeps a positive-definite augmented covariance.
    const Eigen::Vector2d m =
        velocity_noise_variance(motion->v_mps, motion->omega_radps, params_.alpha).cwiseMax(1e-12);
    cov_a.block<2, 2>(kPose, kPose) = m.asDiagonal();
  }
  // Eq. 7: variances (ERRATA: the paper's diagonal writes sigma where sigma^2 is meant).
  for (int k = 0; k < n_b; ++k) cov_a(kPose + n_u + k, kPose + n_u + k) = std::pow(params_.beacon_sigma_m, 2);
  for (int k = 0; k < n_w; ++k) {
    const Eigen::Index i = kPose + n_u + n_b + k;
    cov_a(i, i) = std::pow(params_.laser_sigma_m, 2);
  }
  const UnscentedWeights w(l, params_.unscented);
  const auto chi_a = sigma_points(mean_a, cov_a, w);  // eq. 2
  if (!chi_a) return InputResult::rejected(Rejection::kCovarianceNotPositiveDefinite);
  const Eigen::Index n_sigma = chi_a->cols();

  // Eq. 9-11: every sigma point moved with its own velocity noise (without motion: as it is).
  Eigen::MatrixXd chi_x = chi_a->topRows(3);
  for (Eigen::Index i = 0; motion && i < n_sigma; ++i) {
    if (i > 0 && chi_a->col(i).head(kPose + n_u) == chi_a->col(0).head(kPose + n_u)) {
      chi_x.col(i) = chi_x.col(0);  // a point that spreads only measurement noise moves as the mean
      continue;
    }
    chi_x.col(i) = predict_velocity_motion(Pose2(chi_a->col(i).head<3>()), motion->v_mps + (*chi_a)(kPose, i),
                                           motion->omega_radps + (*chi_a)(kPose + 1, i), motion->dt_s);
  }
  // Eq. 12-13, the heading averaged as offsets from the first sigma point (wrapped).
  const double heading_ref = chi_x(2, 0);
  Eigen::MatrixXd offsets = chi_x;
  for (Eigen::Index i = 0; i < n_sigma; ++i) offsets(2, i) = wrap_angle_rad(chi_x(2, i) - heading_ref);
  Pose2 prior = weighted_mean(offsets, w);
  prior.z() = wrap_angle_rad(prior.z() + heading_ref);
  Eigen::MatrixXd x_centred = chi_x.colwise() - Eigen::Vector3d(prior);
  for (Eigen::Index i = 0; i < n_sigma; ++i) x_centred(2, i) = wrap_angle_rad(x_centred(2, i));
  Cov3 prior_cov = weighted_cross_covariance(x_centred, x_centred, w);
  prior_cov = symmetrized(prior_cov);
  if (motion) {
    mean_ = prior;
    covariance_ = prior_cov;
    last_step_predicted_ = true;
  }
  if (n_b + n_w == 0) return InputResult::ok();

  // Table 2: the predicted range to every beacon over the sigma points, then each measured
  // range's most likely beacon.
  const std::vector<Beacon> beacons = map().beacons();
  std::vector<std::uint32_t> associated(n_b);
  if (n_b > 0) {
    std::vector<PredictedBeaconRange> predicted;
    for (const Beacon& b : beacons) {
      Eigen::VectorXd z(n_sigma);
      for (Eigen::Index i = 0; i < n_sigma; ++i) {
        z(i) = i > 0 && chi_x.col(i) == chi_x.col(0) ? z(0)
                                                     : predict_range(Pose2(chi_x.col(i)), receiver_base_m_,
                                                                     receiver_height_m_, b.position_map_m)
                                                           .range_m;
      }
      const double mean_z = z.dot(w.mean);  // line 3
      const Eigen::RowVectorXd centred = (z.array() - mean_z).matrix().transpose();
      const double var_z = (centred * w.covariance.asDiagonal() * centred.transpose())(0, 0) +
                           std::pow(params_.beacon_sigma_m, 2);  // line 4, with its noise (line 2)
      predicted.push_back({b.id, mean_z, var_z});
    }
    for (int k = 0; k < n_b; ++k) {
      const auto j = most_likely_beacon(ranges[k].range_m, predicted);  // lines 6-11
      if (!j) return InputResult::rejected(Rejection::kNoBeaconToAssociate);
      associated[k] = *j;
    }
  }

  // Eq. 16-20: predicted measurements (beacon ranges, then beams) plus their noise sigma points.
  const Eigen::Index n_z = n_b + n_w;
  Eigen::MatrixXd z_sigma(n_z, n_sigma);
  for (Eigen::Index i = 0; i < n_sigma; ++i) {
    // The sigma points that spread only measurement noise (eq. 8's chi_n^B, chi_n^W) keep the
    // mean's pose: their h is the first point's, computed once (exact, and 5x fewer rays).
    if (i > 0 && chi_x.col(i) == chi_x.col(0)) {
      z_sigma.col(i) = z_sigma.col(0);
      continue;
    }
    const Pose2 pose(chi_x.col(i));
    for (int k = 0; k < n_b; ++k) {
      z_sigma(k, i) =
          predict_range(pose, receiver_base_m_, receiver_height_m_, map().find(associated[k])->position_map_m)
              .range_m;
    }
    if (n_w > 0) expected_laser_ranges(*grid_, pose, scan->beams, z_sigma.col(i).data() + n_b);
  }
  z_sigma += chi_a->bottomRows(n_z);  // eq. 16: + chi_n
  Eigen::VectorXd z_measured(n_z);
  for (int k = 0; k < n_b; ++k) z_measured(k) = ranges[k].range_m;
  for (int k = 0; k < n_w; ++k) z_measured(n_b + k) = scan->ranges_m[k];
  const Eigen::VectorXd z_mean = weighted_mean(z_sigma, w);  // eq. 18
  const Eigen::MatrixXd z_centred = z_sigma.colwise() - z_mean;
  const Eigen::MatrixXd s = weighted_cross_covariance(z_centred, z_centred, w);   // eq. 19
  const Eigen::MatrixXd xz = weighted_cross_covariance(x_centred, z_centred, w);  // eq. 20
  // Eq. 15 prints K = Sigma_xz S; the gain is Sigma_xz S^-1, from a checked LDLT of S.
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(s);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.vectorD().array() > 0.0).all()) {
    return InputResult::rejected(Rejection::kSingularInnovation);
  }
  const Eigen::MatrixXd k_gain = ldlt.solve(xz.transpose()).transpose();
  Pose2 posterior = prior + k_gain * (z_measured - z_mean);  // eq. 21
  posterior.z() = wrap_angle_rad(posterior.z());
  Cov3 posterior_cov = prior_cov - k_gain * s * k_gain.transpose();  // eq. 22
  posterior_cov = symmetrized(posterior_cov);
  if (Eigen::LLT<Cov3>(posterior_cov).info() != Eigen::Success)
    return InputResult::rejected(Rejection::kCovarianceNotPositiveDefinite);
  mean_ = posterior;
  covariance_ = posterior_cov;
  corrected(*now_ns());
  for (int k = 0; k < n_b; ++k) {
    // For evaluation against a simulator's truth; bounded, as no one may ever ask.
    if (associations_.size() >= 4096) associations_.erase(associations_.begin());
    associations_.push_back({ranges[k].stamp_ns, ranges[k].receiver_id, associated[k]});
  }
  return InputResult::ok();
}

std::vector<Estimator::Association> UkfLrf::take_associations() {
  std::vector<Association> out;
  out.swap(associations_);
  return out;
}

bool UkfLrf::place(const Pose2& pose, const Cov3& covariance) {
  mean_ = pose;  // placed by hand again (Sec. 4.1)
  mean_.z() = wrap_angle_rad(mean_.z());
  covariance_ = covariance;
  return true;
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
