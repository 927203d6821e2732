#pragma once
// A robot path as piecewise-constant (linear, angular) velocity segments, integrated exactly
// (straight lines and circular arcs), optionally repeated as a loop.
#include <vector>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc::sim {

struct VelocitySegment {
  double duration_s = 0.0;
  double linear_mps = 0.0;
  double angular_radps = 0.0;
};

class Trajectory {
 public:
  Trajectory() = default;
  Trajectory(const Pose2& start_map_base, std::vector<VelocitySegment> segments, bool loop);

  // Straight legs between waypoints at speed_mps, turning in place at each waypoint at
  // turn_rate_radps; starts at the first waypoint facing the second. Throws on fewer than two
  // waypoints, repeated waypoints or non-positive rates.
  static Trajectory from_waypoints(const std::vector<Eigen::Vector2d>& waypoints_m, double speed_mps,
                                   double turn_rate_radps);

  Pose2 pose_at(double t_s) const;
  // Mean linear and angular velocity over [t0_s, t1_s] (exact integral of the segments).
  void mean_velocity(double t0_s, double t1_s, double& linear_mps, double& angular_radps) const;
  double period_s() const { return period_s_; }  // one lap, or the whole path
  bool loops() const { return loop_; }

 private:
  // Distance and heading change travelled from 0 to t_s.
  void travelled(double t_s, double& distance_m, double& heading_rad) const;

  Pose2 start_ = Pose2::Zero();
  std::vector<VelocitySegment> segments_;
  Pose2 lap_end_ = Pose2::Zero();  // pose after one lap, relative to start_
  double period_s_ = 0.0;
  double lap_distance_m_ = 0.0;
  double lap_heading_rad_ = 0.0;
  bool loop_ = false;
};

// Exact pose after moving at constant (v, w) for t seconds from `from`.
Pose2 integrate_arc(const Pose2& from, double linear_mps, double angular_radps, double t_s);

}  // namespace beaconloc::sim
