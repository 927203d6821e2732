#include "beaconloc/core/occupancy_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace beaconloc {

OccupancyGrid::OccupancyGrid(const Eigen::Vector2d& origin_m, double resolution_m, int width_cells,
                             int height_cells)
    : origin_m_(origin_m), resolution_m_(resolution_m), width_(width_cells), height_(height_cells) {
  if (!(resolution_m > 0.0) || width_cells <= 0 || height_cells <= 0) {
    throw std::invalid_argument("occupancy grid needs a positive resolution and size");
  }
  cells_.assign(static_cast<std::size_t>(width_) * height_, 0);
}

void OccupancyGrid::set_occupied(int ix, int iy, bool occupied) {
  if (inside(ix, iy)) cells_[index(ix, iy)] = occupied ? 1 : 0;
}

void OccupancyGrid::fill_rectangle(const Eigen::Vector2d& min_m, const Eigen::Vector2d& max_m) {
  // Cell centres grow with the index: those inside along an axis are one run of indices. Find the
  // runs of columns and rows, then fill those rows' runs (not every cell of the map: a scenario
  // with many rectangles on a large map took minutes to load).
  const auto run = [&](int count, int axis) {
    std::pair<int, int> first_last{count, -1};
    for (int i = 0; i < count; ++i) {
      const double centre = origin_m_[axis] + resolution_m_ * (i + 0.5);
      if (centre >= min_m[axis] && centre <= max_m[axis]) {
        first_last.first = std::min(first_last.first, i);
        first_last.second = i;
      }
    }
    return first_last;
  };
  const auto [x0, x1] = run(width_, 0);
  const auto [y0, y1] = run(height_, 1);
  if (x0 > x1) return;
  for (int iy = y0; iy <= y1; ++iy) {
    std::fill(cells_.begin() + static_cast<std::ptrdiff_t>(index(x0, iy)),
              cells_.begin() + static_cast<std::ptrdiff_t>(index(x1, iy)) + 1, std::uint8_t{1});
  }
}

void OccupancyGrid::fill_border() {
  for (int ix = 0; ix < width_; ++ix) {
    set_occupied(ix, 0, true);
    set_occupied(ix, height_ - 1, true);
  }
  for (int iy = 0; iy < height_; ++iy) {
    set_occupied(0, iy, true);
    set_occupied(width_ - 1, iy, true);
  }
}

Eigen::Vector2i OccupancyGrid::cell_of(const Eigen::Vector2d& p_m) const {
  const Eigen::Vector2d g = (p_m - origin_m_) / resolution_m_;
  return {static_cast<int>(std::floor(g.x())), static_cast<int>(std::floor(g.y()))};
}

bool OccupancyGrid::occupied_at(const Eigen::Vector2d& p_m) const {
  const Eigen::Vector2i c = cell_of(p_m);
  return occupied(c.x(), c.y());
}

std::optional<double> OccupancyGrid::cast_ray(const Eigen::Vector2d& from_m, double angle_rad,
                                              double max_range_m) const {
  return cast_ray_along(from_m, {std::cos(angle_rad), std::sin(angle_rad)}, max_range_m);
}

std::optional<double> OccupancyGrid::cast_ray_along(const Eigen::Vector2d& from_m,
                                                    const Eigen::Vector2d& direction,
                                                    double max_range_m) const {
  const double dx = direction.x(), dy = direction.y();
  const Eigen::Vector2d g = (from_m - origin_m_) / resolution_m_;  // position in cell units
  int ix = static_cast<int>(std::floor(g.x())), iy = static_cast<int>(std::floor(g.y()));
  if (occupied(ix, iy)) return 0.0;
  const double inf = std::numeric_limits<double>::infinity();
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  // Ray parameter (in metres) at the next vertical / horizontal cell boundary, and per cell.
  const double t_delta_x = dx != 0.0 ? resolution_m_ / std::abs(dx) : inf;
  const double t_delta_y = dy != 0.0 ? resolution_m_ / std::abs(dy) : inf;
  double t_max_x = dx != 0.0 ? ((dx > 0 ? ix + 1 - g.x() : g.x() - ix) * resolution_m_) / std::abs(dx) : inf;
  double t_max_y = dy != 0.0 ? ((dy > 0 ? iy + 1 - g.y() : g.y() - iy) * resolution_m_) / std::abs(dy) : inf;
  // Leaving the grid away from it ends the walk: outside cells are free.
  for (;;) {
    double t;
    if (t_max_x < t_max_y) {
      t = t_max_x;
      ix += step_x;
      t_max_x += t_delta_x;
    } else {
      t = t_max_y;
      iy += step_y;
      t_max_y += t_delta_y;
    }
    if (t > max_range_m) return std::nullopt;
    if (occupied(ix, iy)) return t;
    const bool leaving = (ix < 0 && step_x < 0) || (ix >= width_ && step_x > 0) || (iy < 0 && step_y < 0) ||
                         (iy >= height_ && step_y > 0);
    if (leaving) return std::nullopt;
  }
}

}  // namespace beaconloc
