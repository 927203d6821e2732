#include "beaconloc/core/solvers/range_pose_solver.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

#include "beaconloc/core/models/range_model.hpp"

namespace beaconloc {
namespace {

struct Refined {
  bool converged = false;
  Pose2 pose;
  double cost = std::numeric_limits<double>::infinity();  // sum of squared weighted residuals
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // J^T R^-1 J
};

double weighted_cost(const std::vector<RangeObservation>& obs, const Pose2& pose) {
  double cost = 0.0;
  for (const auto& o : obs) {
    const double r =
        o.range_m - predict_range(pose, o.receiver_solve_frame_m, o.receiver_z_m, o.beacon_map_m).range_m;
    cost += r * r / o.variance_m2;
  }
  return cost;
}

// Gauss-Newton with step halving from one start.
Refined refine(const std::vector<RangeObservation>& obs, Pose2 pose, int max_iterations) {
  Refined out;
  double cost = weighted_cost(obs, pose);
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    for (const auto& o : obs) {
      const RangePrediction p = predict_range(pose, o.receiver_solve_frame_m, o.receiver_z_m, o.beacon_map_m);
      const double w = 1.0 / o.variance_m2;
      info += w * p.jacobian_pose.transpose() * p.jacobian_pose;
      grad += w * p.jacobian_pose.transpose() * (o.range_m - p.range_m);
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(info);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || (ldlt.vectorD().array() <= 1e-12).any()) {
      return out;  // unobservable from these ranges (e.g. all beacons collinear with the robot)
    }
    Eigen::Vector3d step = ldlt.solve(grad);
    double step_scale = 1.0;
    Pose2 candidate;
    double candidate_cost = cost;
    for (int halving = 0; halving < 10; ++halving) {
      candidate = pose + step_scale * step;
      candidate.z() = wrap_angle_rad(candidate.z());
      candidate_cost = weighted_cost(obs, candidate);
      if (candidate_cost <= cost) break;
      step_scale *= 0.5;
    }
    if (candidate_cost > cost) break;  // no descent: at a minimum
    pose = candidate;
    const double improvement = cost - candidate_cost;
    cost = candidate_cost;
    out.information = info;
    if ((step_scale * step).head<2>().norm() < 1e-7 && std::abs(step_scale * step.z()) < 1e-7 &&
        improvement < 1e-9 * (1.0 + cost)) {
      break;
    }
  }
  // Information at the final pose.
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  for (const auto& o : obs) {
    const RangePrediction p = predict_range(pose, o.receiver_solve_frame_m, o.receiver_z_m, o.beacon_map_m);
    info += p.jacobian_pose.transpose() * p.jacobian_pose / o.variance_m2;
  }
  out.converged = true;
  out.pose = pose;
  out.cost = cost;
  out.information = info;
  return out;
}

}  // namespace

RangePoseSolution solve_pose_from_ranges(const std::vector<RangeObservation>& observations,
                                         const RangePoseSolverOptions& options) {
  RangePoseSolution solution;
  if (observations.size() < 4) {
    solution.failure = "too_few_ranges";
    return solution;
  }
  for (const auto& o : observations) {
    if (!std::isfinite(o.range_m) || !(o.variance_m2 > 0.0)) {
      solution.failure = "invalid_observation";
      return solution;
    }
  }
  Eigen::Vector2d lo = observations.front().beacon_map_m.head<2>(), hi = lo;
  for (const auto& o : observations) {
    lo = lo.cwiseMin(o.beacon_map_m.head<2>());
    hi = hi.cwiseMax(o.beacon_map_m.head<2>());
  }
  Refined best;
  const int n = std::max(1, options.position_starts_per_axis);
  for (int ix = 0; ix < n; ++ix) {
    for (int iy = 0; iy < n; ++iy) {
      const double fx = n == 1 ? 0.5 : static_cast<double>(ix) / (n - 1);
      const double fy = n == 1 ? 0.5 : static_cast<double>(iy) / (n - 1);
      for (int k = 0; k < options.yaw_starts; ++k) {
        const Pose2 start(lo.x() + fx * (hi.x() - lo.x()), lo.y() + fy * (hi.y() - lo.y()),
                          wrap_angle_rad(2.0 * M_PI * k / options.yaw_starts));
        const Refined r = refine(observations, start, options.max_iterations);
        if (r.converged && r.cost < best.cost) best = r;
      }
    }
  }
  if (!best.converged) {
    solution.failure = "unobservable";
    return solution;
  }
  solution.weighted_residual_rms = std::sqrt(best.cost / static_cast<double>(observations.size()));
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(best.information);
  if (ldlt.info() != Eigen::Success || (ldlt.vectorD().array() <= 1e-12).any()) {
    solution.failure = "unobservable";
    return solution;
  }
  solution.pose = best.pose;
  solution.covariance = ldlt.solve(Eigen::Matrix3d::Identity());
  if (solution.weighted_residual_rms > options.max_residual_rms_sigma) {
    solution.failure = "residual_too_large";
    return solution;
  }
  solution.ok = true;
  return solution;
}

}  // namespace beaconloc
