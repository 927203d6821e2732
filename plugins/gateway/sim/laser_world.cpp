#include "laser_world.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace beaconloc::sim {

Walker::Walker(std::vector<Eigen::Vector2d> path_m, double speed_mps, double radius_m)
    : path_m_(std::move(path_m)), speed_mps_(speed_mps), radius_m_(radius_m) {
  if (path_m_.size() < 2 || !(speed_mps_ > 0.0) || !(radius_m_ > 0.0) || !std::isfinite(speed_mps_) ||
      !std::isfinite(radius_m_)) {
    throw std::invalid_argument("a walker needs two points or more, a speed and a radius > 0");
  }
  along_m_.push_back(0.0);
  for (std::size_t i = 1; i < path_m_.size(); ++i) along_m_.push_back(along_m_.back() + (path_m_[i] - path_m_[i - 1]).norm());
  if (!(along_m_.back() > 0.0) || !std::isfinite(along_m_.back())) {
    throw std::invalid_argument("a walker's path must have a finite length > 0");
  }
}

Disc Walker::at(double t_s) const {
  const double length_m = along_m_.back();
  // There and back: the distance walked folded onto [0, length].
  double s = std::fmod(std::max(0.0, std::isfinite(t_s) ? t_s : 0.0) * speed_mps_, 2.0 * length_m);
  if (s > length_m) s = 2.0 * length_m - s;
  // The leg holding s: the first point beyond it, from 1 on.
  const auto next = std::upper_bound(along_m_.begin() + 1, along_m_.end() - 1, s);
  const std::size_t i = static_cast<std::size_t>(next - along_m_.begin());
  const double leg_m = along_m_[i] - along_m_[i - 1];
  const double share = leg_m > 0.0 ? std::clamp((s - along_m_[i - 1]) / leg_m, 0.0, 1.0) : 1.0;
  return {path_m_[i - 1] + (path_m_[i] - path_m_[i - 1]) * share, radius_m_};
}

std::vector<Disc> discs_at(const std::vector<Walker>& people, double t_s) {
  std::vector<Disc> out;
  out.reserve(people.size());
  for (const Walker& w : people) out.push_back(w.at(t_s));
  return out;
}

namespace {

// Distance along the unit direction u from p to the disc, if it meets it ahead; nullopt when the
// ray starts inside it or misses it.
std::optional<double> ray_disc_m(const Eigen::Vector2d& p, const Eigen::Vector2d& u, const Disc& disc) {
  const Eigen::Vector2d d = disc.centre_m - p;
  const double c2 = d.squaredNorm() - disc.radius_m * disc.radius_m;
  if (c2 <= 0.0) return std::nullopt;
  const double along = d.dot(u);
  const double discriminant = along * along - c2;
  if (along <= 0.0 || discriminant < 0.0) return std::nullopt;
  return along - std::sqrt(discriminant);
}

}  // namespace

std::optional<double> first_surface_m(const OccupancyGrid& world, const std::vector<Disc>& discs,
                                      const Eigen::Vector2d& from_m, double angle_rad, double max_range_m) {
  const Eigen::Vector2d u(std::cos(angle_rad), std::sin(angle_rad));
  std::optional<double> nearest = world.cast_ray_along(from_m, u, max_range_m);
  for (const Disc& disc : discs) {
    const std::optional<double> hit = ray_disc_m(from_m, u, disc);
    if (hit && *hit <= max_range_m && (!nearest || *hit < *nearest)) nearest = hit;
  }
  return nearest;
}

std::optional<double> spot_reading_m(const OccupancyGrid& world, const std::vector<Disc>& discs,
                                     const LaserSpot& spot, const Eigen::Vector2d& from_m, double angle_rad,
                                     double max_range_m) {
  const std::optional<double> axis = first_surface_m(world, discs, from_m, angle_rad, max_range_m);
  if (spot.ideal()) return axis;
  // Rays across the cone: ray k leaves the screen at offset f * d0 / 2 across the axis and
  // diverges by f * divergence / 2, f from -1 to 1 (the spot's edge at both ends).
  constexpr int kRays = 7;
  const Eigen::Vector2d across(-std::sin(angle_rad), std::cos(angle_rad));
  std::vector<double> hits;
  hits.reserve(kRays);
  for (int k = 0; k < kRays; ++k) {
    const double f = 2.0 * k / (kRays - 1) - 1.0;
    const std::optional<double> hit =
        k == kRays / 2 ? axis
                       : first_surface_m(world, discs, from_m + across * (f * spot.diameter_at_window_m / 2.0),
                                         angle_rad + f * spot.divergence_rad / 2.0, max_range_m);
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
