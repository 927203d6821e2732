#include "laser_world.hpp"

#include <algorithm>
#include <cmath>

namespace beaconloc::sim {

Eigen::Vector2d Walker::position_at(double t_s) const {
  if (path_m.size() < 2 || !(speed_mps > 0.0)) return path_m.empty() ? Eigen::Vector2d::Zero() : path_m.front();
  double length_m = 0.0;
  for (std::size_t i = 1; i < path_m.size(); ++i) length_m += (path_m[i] - path_m[i - 1]).norm();
  if (!(length_m > 0.0)) return path_m.front();
  // There and back: the distance walked folded onto [0, length].
  double s = std::fmod(std::max(0.0, t_s) * speed_mps, 2.0 * length_m);
  if (s > length_m) s = 2.0 * length_m - s;
  for (std::size_t i = 1; i < path_m.size(); ++i) {
    const double leg_m = (path_m[i] - path_m[i - 1]).norm();
    if (s <= leg_m || i + 1 == path_m.size()) {
      return leg_m > 0.0 ? path_m[i - 1] + (path_m[i] - path_m[i - 1]) * std::min(1.0, s / leg_m) : path_m[i];
    }
    s -= leg_m;
  }
  return path_m.back();
}

namespace {

// Distance along the unit direction u from p to the disc (centre c, radius r), if it meets it
// ahead; nullopt when the ray starts inside it or misses it.
std::optional<double> ray_disc_m(const Eigen::Vector2d& p, const Eigen::Vector2d& u, const Eigen::Vector2d& c,
                                 double r) {
  const Eigen::Vector2d d = c - p;
  const double c2 = d.squaredNorm() - r * r;
  if (c2 <= 0.0) return std::nullopt;
  const double along = d.dot(u);
  const double disc = along * along - c2;
  if (along <= 0.0 || disc < 0.0) return std::nullopt;
  return along - std::sqrt(disc);
}

}  // namespace

std::optional<double> first_surface_m(const OccupancyGrid& world, const std::vector<Walker>& people, double t_s,
                                      const Eigen::Vector2d& from_m, double angle_rad, double max_range_m) {
  const Eigen::Vector2d u(std::cos(angle_rad), std::sin(angle_rad));
  std::optional<double> nearest = world.cast_ray_along(from_m, u, max_range_m);
  for (const Walker& w : people) {
    const std::optional<double> hit = ray_disc_m(from_m, u, w.position_at(t_s), w.radius_m);
    if (hit && *hit <= max_range_m && (!nearest || *hit < *nearest)) nearest = hit;
  }
  return nearest;
}

std::optional<double> spot_reading_m(const OccupancyGrid& world, const std::vector<Walker>& people, double t_s,
                                     const LaserSpot& spot, const Eigen::Vector2d& from_m, double angle_rad,
                                     double max_range_m) {
  const std::optional<double> axis = first_surface_m(world, people, t_s, from_m, angle_rad, max_range_m);
  if (spot.ideal()) return axis;
  // The spot's half width, as an angle, at the distance its axis meets (or at the range limit).
  const double at_m = std::max(axis.value_or(max_range_m), 1e-3);
  const double half_angle_rad = std::atan((spot.diameter_at_window_m + spot.divergence_rad * at_m) / (2.0 * at_m));
  constexpr int kSubRays = 7;
  std::vector<double> hits;
  hits.reserve(kSubRays);
  for (int k = 0; k < kSubRays; ++k) {
    const double offset = half_angle_rad * (2.0 * k / (kSubRays - 1) - 1.0);
    const std::optional<double> hit = k == kSubRays / 2 ? axis : first_surface_m(world, people, t_s, from_m,
                                                                                 angle_rad + offset, max_range_m);
    if (hit) hits.push_back(*hit);
  }
  if (hits.empty()) return std::nullopt;
  const double nearest_m = *std::min_element(hits.begin(), hits.end());
  double sum_m = 0.0;
  int merged = 0;
  for (const double h : hits) {
    if (h <= nearest_m + spot.echo_merge_m) {
      sum_m += h;
      ++merged;
    }
  }
  return sum_m / merged;
}

}  // namespace beaconloc::sim
