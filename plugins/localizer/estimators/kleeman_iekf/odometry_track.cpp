#include "kleeman_iekf/odometry_track.hpp"

#include <algorithm>
#include <cmath>

namespace beaconloc::kleeman {

void OdometryTrack::add(const OdometrySample& o, double end_s, double dt_s) {
  const double base = o.wheel_base_m;
  const Eigen::Matrix2d& c = o.wheel_velocity_covariance;  // over (right, left)
  OdometryInterval i;
  i.start_s = end_s - dt_s;
  i.end_s = end_s;
  i.speed_mps = 0.5 * (o.wheel_velocity_right_mps + o.wheel_velocity_left_mps);
  i.turn_rate_radps = (o.wheel_velocity_right_mps - o.wheel_velocity_left_mps) / base;
  i.speed_variance_m2ps2 = 0.25 * (c(0, 0) + c(1, 1) + 2.0 * c(0, 1));
  i.turn_rate_variance_rad2ps2 = (c(0, 0) + c(1, 1) - 2.0 * c(0, 1)) / (base * base);
  intervals_.push_back(i);
}

namespace {
// Moves (forward, left, heading) along an arc of `distance` turning by `dtheta`, exactly.
void move_along(DeadReckoning& d, double heading_rad, double distance, double dtheta) {
  const double mid = heading_rad + 0.5 * dtheta;
  // The chord of the arc: 2 sin(dtheta/2)/dtheta of its length, along its middle heading.
  const double chord = std::abs(dtheta) < 1e-9 ? distance : distance * std::sin(0.5 * dtheta) / (0.5 * dtheta);
  d.forward_m += chord * std::cos(mid);
  d.left_m += chord * std::sin(mid);
}
}  // namespace

DeadReckoning OdometryTrack::between(double from_s, double to_s) const {
  DeadReckoning d;
  if (!(to_s > from_s)) return d;
  const auto add_stretch = [&d](const OdometryInterval& i, double a, double b) {
    const double dt = b - a;
    if (!(dt > 0.0)) return;
    const double distance = i.speed_mps * dt, dtheta = i.turn_rate_radps * dt;
    move_along(d, d.dtheta_rad, distance, dtheta);
    d.distance_m += distance;
    d.dtheta_rad += dtheta;
    d.distance_variance_m2 += i.speed_variance_m2ps2 * dt * dt;
    d.dtheta_variance_rad2 += i.turn_rate_variance_rad2ps2 * dt * dt;
  };
  // The first interval that ends after from_s.
  auto it = std::upper_bound(intervals_.begin(), intervals_.end(), from_s,
                             [](double t, const OdometryInterval& i) { return t < i.end_s; });
  for (; it != intervals_.end() && it->start_s < to_s; ++it) {
    add_stretch(*it, std::max(from_s, it->start_s), std::min(to_s, it->end_s));
  }
  if (!intervals_.empty() && to_s > intervals_.back().end_s) {
    const double from = std::max(from_s, intervals_.back().end_s);
    add_stretch(intervals_.back(), from, to_s);
    d.extrapolated_s = to_s - from;
  }
  return d;
}

void OdometryTrack::forget_before(double s) {
  while (!intervals_.empty() && intervals_.front().end_s < s) intervals_.pop_front();
}

}  // namespace beaconloc::kleeman
