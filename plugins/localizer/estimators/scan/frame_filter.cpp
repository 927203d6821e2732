#include "scan/frame_filter.hpp"

#include <stdexcept>

#include "beaconloc/core/chi_square.hpp"

namespace beaconloc::scan {
namespace {

std::variant<Ekf<3>, Ukf<3>, HInfinityFilter<3>> make_filter(const FrameFilterSettings& s) {
  switch (s.kind) {
    case FilterKind::kEkf: return Ekf<3>(pose_space());
    case FilterKind::kUkf: return Ukf<3>(pose_space(), UkfOptions{s.unscented, false});
    case FilterKind::kHInfinity: return HInfinityFilter<3>(pose_space(), s.h_infinity_theta);
  }
  throw std::invalid_argument("FrameFilter: unknown filter kind");
}

}  // namespace

const char* to_string(FilterKind kind) {
  switch (kind) {
    case FilterKind::kEkf: return "ekf";
    case FilterKind::kUkf: return "ukf";
    case FilterKind::kHInfinity: return "h_infinity";
  }
  return "unknown";
}

FrameFilter::FrameFilter(const FrameFilterSettings& settings)
    : settings_(settings), kind_(settings.kind), filter_(make_filter(settings)) {}

FilterOutcome FrameFilter::start(const Pose2& pose_frame_base, const Cov3& covariance) {
  return std::visit([&](auto& f) { return f.reset(pose_frame_base, covariance); }, filter_);
}

Pose2 FrameFilter::pose() const {
  return std::visit([](const auto& f) -> Pose2 { return f.state(); }, filter_);
}

Cov3 FrameFilter::covariance() const {
  return std::visit([](const auto& f) -> Cov3 { return f.covariance(); }, filter_);
}

PredictResult FrameFilter::predict(const OdometrySample& o, double dt_s, double wheel_variance_floor_m2ps2) {
  const DiffDriveMotion motion(o.wheel_base_m, o.wheel_velocity_covariance +
                                                   wheel_variance_floor_m2ps2 * Eigen::Matrix2d::Identity());
  const Eigen::Vector2d u(o.wheel_velocity_right_mps, o.wheel_velocity_left_mps);
  return std::visit([&](auto& f) { return f.predict(motion, u, dt_s); }, filter_);
}

template <class Model>
UpdateResult FrameFilter::update(const Model& model, const typename Model::Vector& z, double nis_gate) {
  return std::visit([&](auto& f) { return f.update(model, z, nis_gate); }, filter_);
}

UpdateResult FrameFilter::update_range(const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                                       const Eigen::Vector3d& beacon_frame_m, double range_m, double variance_m2) {
  const RangeModel model(receiver_base_m, receiver_z_m, beacon_frame_m, variance_m2);  // eq. 26, 18
  return update(model, RangeModel::Vector(range_m), kChiSquare999OneDof);
}

UpdateResult FrameFilter::update_differences(const Eigen::Vector2d& receiver_base_m, double receiver_z_m,
                                             const std::vector<EpochRange>& ranges, const Pose2& end_odometry_pose,
                                             double range_variance_m2) {
  UpdateResult refused;
  if (ranges.size() < 2) {
    refused.outcome = FilterOutcome::kSizeMismatch;
    return refused;
  }
  std::vector<Eigen::Vector3d> beacons;
  beacons.reserve(ranges.size());
  for (const EpochRange& r : ranges) beacons.push_back(r.beacon_frame_m);
  const std::vector<double> at_end = ranges_at_end(pose(), receiver_base_m, receiver_z_m, ranges, end_odometry_pose);
  Eigen::VectorXd z(static_cast<Eigen::Index>(ranges.size()) - 1);
  for (Eigen::Index i = 0; i < z.size(); ++i) z(i) = at_end[static_cast<std::size_t>(i) + 1] - at_end[0];  // eq. 27
  // Eq. 19's sigma_vT^2 is one difference's variance: two independent ranges, twice one range's.
  const RangeDifferenceModel model(receiver_base_m, receiver_z_m, std::move(beacons), 2.0 * range_variance_m2);
  return update(model, z, chi_square_quantile_999(static_cast<int>(z.size())));
}

std::vector<double> ranges_at_end(const Pose2& pose_frame_end, const Eigen::Vector2d& receiver_base_m,
                                  double receiver_z_m, const std::vector<EpochRange>& ranges,
                                  const Pose2& end_odometry_pose) {
  std::vector<double> out;
  out.reserve(ranges.size());
  for (const EpochRange& r : ranges) {
    // Where the robot was at the range, seen from where it is now (odometry), put in the frame.
    const Pose2 then = compose(pose_frame_end, between(end_odometry_pose, r.odometry_pose));
    const double now_m = predict_range(pose_frame_end, receiver_base_m, receiver_z_m, r.beacon_frame_m).range_m;
    const double then_m = predict_range(then, receiver_base_m, receiver_z_m, r.beacon_frame_m).range_m;
    out.push_back(r.range_m + now_m - then_m);
  }
  return out;
}

}  // namespace beaconloc::scan
