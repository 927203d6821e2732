#pragma once
// Global pose from ranges alone, no prior: nonlinear least squares (Gauss-Newton) on [x, y, yaw]
// from several starts. Used to initialize (and re-initialize) filters that track a pose.
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

// Fewer ranges than this leave the three unknowns without a residual to judge the fix by.
constexpr std::size_t kRangePoseMinObservations = 4;

struct RangeObservation {
  Eigen::Vector2d receiver_solve_frame_m;  // receiver in the frame of the pose solved for
  double receiver_z_m = 0.0;
  Eigen::Vector3d beacon_map_m = Eigen::Vector3d::Zero();
  double range_m = 0.0;
  double variance_m2 = 1e-4;
};

struct RangePoseSolverOptions {
  int yaw_starts = 12;               // starting headings, evenly spread
  int position_starts_per_axis = 3;  // grid over the beacons' bounding box
  int max_iterations = 30;
  double max_residual_rms_sigma = 3.0;  // accept when the weighted residual RMS is below this
  // Outliers (echoes: a reflection's longer path) pull a least-squares fix away from the pose.
  // When > 0, the range with the largest residual is dropped while it exceeds this many sigma,
  // up to max_outlier_fraction of them, and the rest solved again. 0: every range is kept.
  double outlier_gate_sigma = 0.0;
  double max_outlier_fraction = 0.4;
};

struct RangePoseSolution {
  bool ok = false;
  Pose2 pose = Pose2::Zero();
  Cov3 covariance = Cov3::Identity();  // (J^T R^-1 J)^-1 at the solution
  double weighted_residual_rms = 0.0;  // residuals in units of their sigma (of the ranges kept)
  std::size_t outliers = 0;            // ranges dropped by the outlier gate
  // The mirror image: Gauss-Newton from the fix reflected across the principal axis of the
  // beacons it used (position and heading mirrored), on the same ranges. Its weighted cost less
  // the fix's (a chi-square difference); +inf when that refinement finds no minimum or returns
  // to the fix (within its covariance, chi-square 3 dof 99.9 %). Near 0 when the beacons lie on
  // one line and the receivers cannot tell the two sides apart (one receiver, or a path along a
  // straight line): the ranges do not say which of the two poses is the robot's. When the
  // mirror fits better, it is the fix and the old fix its mirror.
  double mirror_cost_margin = std::numeric_limits<double>::infinity();
  std::string failure;  // why ok is false
};

RangePoseSolution solve_pose_from_ranges(const std::vector<RangeObservation>& observations,
                                         const RangePoseSolverOptions& options = {});

// How well a pose explains ranges that may hold outliers: the sum of the squared residuals in
// sigma, each capped at cap_sigma^2 (an echo costs as much however long its path). To compare
// two poses on the same ranges.
double truncated_range_cost(const std::vector<RangeObservation>& observations, const Pose2& pose,
                            double cap_sigma);

}  // namespace beaconloc
