#include "scan/frame_start.hpp"

#include <cmath>
#include <stdexcept>

#include "beaconloc/core/models/diff_drive_motion.hpp"

namespace beaconloc::scan {
namespace {

// The unit vector across v (v turned by +90 degrees, normalized).
Eigen::Vector2d across(const Eigen::Vector2d& v) { return Eigen::Vector2d(-v.y(), v.x()) / v.norm(); }

}  // namespace

FrameStart::FrameStart(const FrameStartSettings& settings) : settings_(settings) {
  if (!(settings.heading_baseline_m > 0.0) || !std::isfinite(settings.heading_baseline_m) ||
      !(settings.max_disagreement_sigma > 0.0)) {
    throw std::invalid_argument("FrameStart: heading_baseline_m and max_disagreement_sigma must be finite and > 0");
  }
}

PredictResult FrameStart::predict(const OdometrySample& o, double dt_s, double wheel_variance_floor_m2ps2) {
  if (!first_) return {};
  const DiffDriveMotion motion(o.wheel_base_m, o.wheel_velocity_covariance +
                                                   wheel_variance_floor_m2ps2 * Eigen::Matrix2d::Identity());
  return odometry_since_first_.predict(motion, Eigen::Vector2d(o.wheel_velocity_right_mps, o.wheel_velocity_left_mps),
                                       dt_s);
}

double FrameStart::displacement_m() const {
  return first_ ? odometry_since_first_.state().head<2>().norm() : 0.0;
}

std::optional<FrameBelief> FrameStart::add_fix(const GroupFix& fix) {
  if (!fix.ok()) return std::nullopt;
  const auto restart_from = [this](const GroupFix& f) {
    first_ = f;
    odometry_since_first_.reset(Pose2::Zero(), Cov3::Zero());
  };
  if (!first_) {
    restart_from(fix);
    return std::nullopt;
  }
  const Eigen::Vector2d chord = fix.position_m - first_->position_m;  // in the frame
  const Pose2 moved = odometry_since_first_.state();                  // in the robot's frame at the first fix
  const Cov3 moved_cov = odometry_since_first_.covariance();
  const Eigen::Vector2d step = moved.head<2>();
  if (step.norm() < settings_.heading_baseline_m) return std::nullopt;  // wait: the chord is too short
  // Both say how far the robot went: the fixes along their chord, the odometry along its step.
  if (chord.norm() < 0.5 * settings_.heading_baseline_m) {  // the fixes say it barely moved: one is wrong
    restart_from(fix);
    return std::nullopt;
  }
  const Eigen::Vector2d along_chord = chord.normalized();
  const Eigen::Vector2d along_step = step.normalized();
  const double distance_variance = along_chord.dot((first_->covariance_m2 + fix.covariance_m2) * along_chord) +
                                   along_step.dot(moved_cov.topLeftCorner<2, 2>() * along_step);
  if (!(std::abs(chord.norm() - step.norm()) <= settings_.max_disagreement_sigma * std::sqrt(distance_variance))) {
    restart_from(fix);  // one of the two fixes is wrong: the newer may be right, start from it
    return std::nullopt;
  }
  // Heading at the first fix: the chord's direction in the frame less the step's in the robot's
  // frame; at the newer fix, plus the odometry's turn since.
  const double chord_rad = std::atan2(chord.y(), chord.x());
  const double step_rad = std::atan2(step.y(), step.x());
  const Eigen::Vector2d chord_across = across(chord);
  const Eigen::Vector2d step_across = across(step);
  const double chord_variance =
      chord_across.dot((first_->covariance_m2 + fix.covariance_m2) * chord_across) / chord.squaredNorm();
  const double step_variance = step_across.dot(moved_cov.topLeftCorner<2, 2>() * step_across) / step.squaredNorm();
  FrameBelief belief;
  belief.pose_frame_base << fix.position_m, wrap_angle_rad(chord_rad - step_rad + moved.z());
  belief.covariance.setZero();
  belief.covariance.topLeftCorner<2, 2>() = fix.covariance_m2;
  // The step's angle and the turn both come from the odometry: their covariance counted at its
  // worst (fully correlated), so the heading's variance is not under-stated.
  const double turn_sigma = std::sqrt(moved_cov(2, 2));
  belief.covariance(2, 2) = chord_variance + std::pow(std::sqrt(step_variance) + turn_sigma, 2);
  // The heading moves with the newer fix across the chord: cov(p, heading) = C u_across / |chord|.
  const Eigen::Vector2d cross = fix.covariance_m2 * chord_across / chord.norm();
  belief.covariance.block<2, 1>(0, 2) = cross;
  belief.covariance.block<1, 2>(2, 0) = cross.transpose();
  first_.reset();
  return belief;
}

}  // namespace beaconloc::scan
