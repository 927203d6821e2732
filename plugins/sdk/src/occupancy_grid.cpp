#include "beaconloc/core/occupancy_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "beaconloc/core/limits.hpp"

namespace beaconloc {

OccupancyGrid::OccupancyGrid(const Eigen::Vector2d& origin_m, double resolution_m, int width_cells,
                             int height_cells)
    : origin_m_(origin_m), resolution_m_(resolution_m), width_(width_cells), height_(height_cells) {
  std::ostringstream why;
  if (!(resolution_m >= kMinResolutionM && resolution_m <= kMaxResolutionM)) {
    why << "resolution " << resolution_m << " m outside [" << kMinResolutionM << ", " << kMaxResolutionM
        << "]";
  } else if (width_cells <= 0 || height_cells <= 0 || width_cells > kMaxCellsPerSide ||
             height_cells > kMaxCellsPerSide || std::int64_t{width_cells} * height_cells > kMaxCells) {
    why << width_cells << " x " << height_cells << " cells: not 1.." << kMaxCellsPerSide << " a side, "
        << kMaxCells << " in all";
  } else if (!(origin_m.cwiseAbs().maxCoeff() <= kMaxMapCoordinateM)) {
    why << "origin (" << origin_m.x() << ", " << origin_m.y() << ") not within " << kMaxMapCoordinateM
        << " m";
  }
  if (!why.str().empty()) throw std::invalid_argument("occupancy grid: " + why.str());
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
  // Clamped before the conversion: a double beyond int (or NaN) has no int.
  const auto axis = [](double v, int size) {
    return static_cast<int>(std::floor(std::clamp(v, -1.0, static_cast<double>(size))));
  };
  if (!g.allFinite()) return {-1, -1};
  return {axis(g.x(), width_), axis(g.y(), height_)};
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
  if (cells_.empty() || !from_m.allFinite() || !direction.allFinite() || std::isnan(max_range_m) ||
      max_range_m < 0.0) {
    return std::nullopt;
  }
  // In cell units from here: the ray is g + t d, t in cells along a unit d.
  const Eigen::Vector2d g = (from_m - origin_m_) / resolution_m_;
  const double range = max_range_m / resolution_m_;
  const double inf = std::numeric_limits<double>::infinity();
  // Where the ray is inside the grid's box [0, width] x [0, height]: t in [t_in, t_out].
  double t_in = 0.0, t_out = inf;
  const double size[2] = {static_cast<double>(width_), static_cast<double>(height_)};
  for (int a = 0; a < 2; ++a) {
    if (direction[a] == 0.0) {
      if (!(g[a] >= 0.0 && g[a] < size[a])) return std::nullopt;  // parallel to the box, beside it
      continue;
    }
    double t0 = -g[a] / direction[a], t1 = (size[a] - g[a]) / direction[a];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  if (!(t_in < t_out) || t_in > range) return std::nullopt;  // misses the grid, or beyond the range
  // The first cell of the grid on the ray (clamped: the entry point lies on the box's edge).
  const Eigen::Vector2d entry = g + t_in * direction;
  int ix = std::clamp(static_cast<int>(std::floor(std::clamp(entry.x(), 0.0, size[0]))), 0, width_ - 1);
  int iy = std::clamp(static_cast<int>(std::floor(std::clamp(entry.y(), 0.0, size[1]))), 0, height_ - 1);
  if (occupied(ix, iy)) return t_in * resolution_m_;
  const double dx = direction.x(), dy = direction.y();
  if (dx == 0.0 && dy == 0.0) return std::nullopt;
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  // Ray parameter at the next vertical / horizontal cell boundary, and per cell.
  const double t_delta_x = dx != 0.0 ? 1.0 / std::abs(dx) : inf;
  const double t_delta_y = dy != 0.0 ? 1.0 / std::abs(dy) : inf;
  double t_max_x = dx != 0.0 ? (dx > 0 ? ix + 1 - g.x() : g.x() - ix) / std::abs(dx) : inf;
  double t_max_y = dy != 0.0 ? (dy > 0 ? iy + 1 - g.y() : g.y() - iy) / std::abs(dy) : inf;
  // Each step moves one cell along x or y, never back: the ray leaves the grid within
  // width + height steps, and cells outside it are free.
  for (int steps = 0; steps < width_ + height_; ++steps) {
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
    if (!(t <= range) || !inside(ix, iy)) return std::nullopt;
    if (occupied(ix, iy)) return t * resolution_m_;
  }
  return std::nullopt;
}

}  // namespace beaconloc
