#include "trajectory.hpp"

#include <cmath>

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
