#include "beaconloc/core/solvers/range_pose_solver.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
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

// Index of the range with the largest residual in sigma at the pose, and that residual.
std::pair<std::size_t, double> worst_residual(const std::vector<RangeObservation>& obs, const Pose2& pose) {
  std::pair<std::size_t, double> worst{0, -1.0};
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const double r = std::abs(obs[i].range_m - predict_range(pose, obs[i].receiver_solve_frame_m,
                                                             obs[i].receiver_z_m, obs[i].beacon_map_m)
                                                   .range_m) /
                     std::sqrt(obs[i].variance_m2);
    if (r > worst.second) worst = {i, r};
  }
  return worst;
}

// Gauss-Newton from a grid of starts over the beacons' bounding box and evenly spread headings;
// the converged fix of least cost.
Refined best_of_starts(const std::vector<RangeObservation>& observations,
                       const RangePoseSolverOptions& options) {
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
  return best;
}

// Chi-square, 3 dof, 99.9 %: two minima closer than this in the fix's information are one.
constexpr double kSameMinimumChiSquare = 16.27;

// The pose reflected across the principal axis of the observations' beacons (map xy): with the
// beacons on one line, the ranges from receivers mirrored across it are the same.
Pose2 mirrored_across_beacon_axis(const std::vector<RangeObservation>& obs, const Pose2& pose) {
  std::vector<Eigen::Vector2d> beacons;
  for (const auto& o : obs) {
    const Eigen::Vector2d b = o.beacon_map_m.head<2>();
    if (std::find(beacons.begin(), beacons.end(), b) == beacons.end()) beacons.push_back(b);
  }
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& b : beacons) mean += b;
  mean /= static_cast<double>(beacons.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto& b : beacons) scatter += (b - mean) * (b - mean).transpose();
  // Eigenvalues ascending: the last eigenvector is the axis along which the beacons spread most.
  const Eigen::Vector2d axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvectors().col(1);
  const Eigen::Matrix2d reflection = 2.0 * axis * axis.transpose() - Eigen::Matrix2d::Identity();
  const Eigen::Vector2d position = mean + reflection * (pose.head<2>() - mean);
  const double axis_angle = std::atan2(axis.y(), axis.x());
  return {position.x(), position.y(), wrap_angle_rad(2.0 * axis_angle - pose.z())};
}

bool same_minimum(const Refined& a, const Refined& b) {
  const Eigen::Vector3d d = pose_difference(a.pose, b.pose);
  return d.dot(b.information * d) < kSameMinimumChiSquare;
}

}  // namespace

RangePoseSolution solve_pose_from_ranges(const std::vector<RangeObservation>& all_observations,
                                         const RangePoseSolverOptions& options) {
  std::vector<RangeObservation> observations = all_observations;
  RangePoseSolution solution;
  if (observations.size() < kRangePoseMinObservations) {
    solution.failure = "too_few_ranges";
    return solution;
  }
  for (const auto& o : observations) {
    if (!std::isfinite(o.range_m) || !(o.variance_m2 > 0.0)) {
      solution.failure = "invalid_observation";
      return solution;
    }
  }
  Refined best = best_of_starts(observations, options);
  if (!best.converged) {
    solution.failure = "unobservable";
    return solution;
  }
  if (options.outlier_gate_sigma > 0.0) {
    const auto max_outliers =
        static_cast<std::size_t>(options.max_outlier_fraction * static_cast<double>(observations.size()));
    for (;;) {
      const auto [worst, sigma] = worst_residual(observations, best.pose);
      if (sigma <= options.outlier_gate_sigma) break;
      if (solution.outliers >= max_outliers || observations.size() <= kRangePoseMinObservations) {
        solution.failure = "too_many_outliers";
        return solution;
      }
      observations.erase(observations.begin() + static_cast<std::ptrdiff_t>(worst));
      ++solution.outliers;
      // From where the fix was: once the worst ranges are out, it moves toward the pose.
      const Refined r = refine(observations, best.pose, options.max_iterations);
      if (!r.converged) {
        solution.failure = "unobservable";
        return solution;
      }
      best = r;
    }
    if (solution.outliers > 0) {
      // The fix the ranges were judged by was found with the outliers in; with them out, every
      // start again, in case they had pulled it into another basin.
      const Refined again = best_of_starts(observations, options);
      if (again.converged && again.cost < best.cost) best = again;
    }
  }
  const Refined mirror =
      refine(observations, mirrored_across_beacon_axis(observations, best.pose), options.max_iterations);
  if (mirror.converged && !same_minimum(mirror, best)) {
    solution.mirror_cost_margin = std::abs(mirror.cost - best.cost);
    if (mirror.cost < best.cost) best = mirror;  // the starts missed it: the mirror is the fix
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

double truncated_range_cost(const std::vector<RangeObservation>& obs, const Pose2& pose, double cap_sigma) {
  double cost = 0.0;
  for (const auto& o : obs) {
    const double r =
        o.range_m - predict_range(pose, o.receiver_solve_frame_m, o.receiver_z_m, o.beacon_map_m).range_m;
    cost += std::min(r * r / o.variance_m2, cap_sigma * cap_sigma);
  }
  return cost;
}

}  // namespace beaconloc
