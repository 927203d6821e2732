#include "trajectory.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace beaconloc::sim {

Pose2 integrate_arc(const Pose2& from, double v, double w, double t) {
  const double yaw = from.z();
  if (std::abs(w * t) < 1e-12) {
    return {from.x() + v * t * std::cos(yaw), from.y() + v * t * std::sin(yaw), yaw};
  }
  const double r = v / w;
  const double yaw1 = yaw + w * t;
  return {from.x() + r * (std::sin(yaw1) - std::sin(yaw)), from.y() - r * (std::cos(yaw1) - std::cos(yaw)),
          wrap_angle_rad(yaw1)};
}

Trajectory Trajectory::from_waypoints(const std::vector<Eigen::Vector2d>& waypoints, double speed,
                                      double turn_rate) {
  if (waypoints.size() < 2) throw std::invalid_argument("a waypoint path needs at least two waypoints");
  if (!(speed > 0.0) || !(turn_rate > 0.0)) {
    throw std::invalid_argument("a waypoint path needs speed_mps > 0 and turn_rate_radps > 0");
  }
  std::vector<VelocitySegment> segments;
  const Eigen::Vector2d first_leg = waypoints[1] - waypoints[0];
  double heading = std::atan2(first_leg.y(), first_leg.x());
  const Pose2 start(waypoints[0].x(), waypoints[0].y(), heading);
  for (std::size_t i = 0; i + 1 < waypoints.size(); ++i) {
    const Eigen::Vector2d leg = waypoints[i + 1] - waypoints[i];
    if (leg.norm() < 1e-9)
      throw std::invalid_argument("waypoints " + std::to_string(i) + " and " + std::to_string(i + 1) +
                                  " coincide");
    const double turn = wrap_angle_rad(std::atan2(leg.y(), leg.x()) - heading);
    if (std::abs(turn) > 1e-12) {
      segments.push_back({std::abs(turn) / turn_rate, 0.0, turn > 0 ? turn_rate : -turn_rate});
    }
    segments.push_back({leg.norm() / speed, speed, 0.0});
    heading += turn;
  }
  return Trajectory(start, std::move(segments), false);
}

Trajectory::Trajectory(const Pose2& start, std::vector<VelocitySegment> segments, bool loop)
    : start_(start), segments_(std::move(segments)), loop_(loop) {
  Pose2 p = start_;
  for (const auto& s : segments_) {
    p = integrate_arc(p, s.linear_mps, s.angular_radps, s.duration_s);
    period_s_ += s.duration_s;
    lap_distance_m_ += s.linear_mps * s.duration_s;
    lap_heading_rad_ += s.angular_radps * s.duration_s;
  }
  lap_end_ = between(start_, p);
}

Pose2 Trajectory::pose_at(double t) const {
  Pose2 p = start_;
  if (t <= 0.0) return p;
  if (loop_ && period_s_ > 0.0) {
    // Segments are body-frame velocities: every lap moves the robot by the same lap_end_.
    const double laps = std::floor(t / period_s_);
    for (int i = 0; i < static_cast<int>(laps); ++i) p = compose(p, lap_end_);
    t -= laps * period_s_;
  }
  for (const auto& s : segments_) {
    const double dt = std::min(t, s.duration_s);
    p = integrate_arc(p, s.linear_mps, s.angular_radps, dt);
    t -= dt;
    if (t <= 0.0) break;
  }
  return p;  // past the end of a non-looping path: standing at its end
}

void Trajectory::travelled(double t, double& distance_m, double& heading_rad) const {
  distance_m = 0.0;
  heading_rad = 0.0;
  if (t <= 0.0 || segments_.empty()) return;
  if (loop_ && period_s_ > 0.0) {
    const double laps = std::floor(t / period_s_);
    distance_m += laps * lap_distance_m_;
    heading_rad += laps * lap_heading_rad_;
    t -= laps * period_s_;
  }
  for (const auto& s : segments_) {
    const double dt = std::min(t, s.duration_s);
    distance_m += s.linear_mps * dt;
    heading_rad += s.angular_radps * dt;
    t -= dt;
    if (t <= 0.0) break;
  }
}

void Trajectory::mean_velocity(double t0, double t1, double& linear, double& angular) const {
  double d0, h0, d1, h1;
  travelled(t0, d0, h0);
  travelled(t1, d1, h1);
  const double dt = t1 - t0;
  linear = dt > 0.0 ? (d1 - d0) / dt : 0.0;
  angular = dt > 0.0 ? (h1 - h0) / dt : 0.0;
}

}  // namespace beaconloc::sim
