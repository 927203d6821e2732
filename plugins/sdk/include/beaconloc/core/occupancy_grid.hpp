#pragma once
// Occupancy grid of the map and ray casting on it (exact cell traversal, Amanatides & Woo):
// the simulator's laser and the laser measurement model of the estimators share it.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

namespace beaconloc {

class OccupancyGrid {
 public:
  // What a grid may be: the constructor refuses anything else, and every loader (map files,
  // scenario maps) checks each of its numbers against these first, naming the key.
  static constexpr double kMinResolutionM = 1e-3;  // 1 mm cells
  static constexpr double kMaxResolutionM = 10.0;
  static constexpr int kMaxCellsPerSide = 20000;
  static constexpr std::int64_t kMaxCells = 100'000'000;
  // The origin's coordinates lie within kMaxMapCoordinateM (core/limits.hpp).

  OccupancyGrid() = default;
  // origin_m: map-frame position of the lower-left corner of cell (0, 0). Throws
  // std::invalid_argument beyond the limits above.
  OccupancyGrid(const Eigen::Vector2d& origin_m, double resolution_m, int width_cells, int height_cells);

  int width() const { return width_; }
  int height() const { return height_; }
  double resolution_m() const { return resolution_m_; }
  const Eigen::Vector2d& origin_m() const { return origin_m_; }
  bool inside(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < width_ && iy < height_; }
  bool occupied(int ix, int iy) const { return inside(ix, iy) && cells_[index(ix, iy)] != 0; }
  void set_occupied(int ix, int iy, bool occupied);
  // Marks every cell whose centre lies in the rectangle (map frame).
  void fill_rectangle(const Eigen::Vector2d& min_m, const Eigen::Vector2d& max_m);
  void fill_border();
  // Cell containing a map-frame point (floor of the coordinates); may be outside the grid (a
  // point far outside, or not finite, gives a cell one beyond the grid's edge, -1 or the size).
  Eigen::Vector2i cell_of(const Eigen::Vector2d& p_m) const;
  bool occupied_at(const Eigen::Vector2d& p_m) const;

  // Distance from `from_m` along the direction angle_rad (map frame) to the boundary of the first
  // occupied cell; nullopt when none lies within max_range_m (cells outside the grid are free).
  // A start inside an occupied cell gives 0. Bounded by construction: a ray visits at most
  // width + height cells of the grid, wherever it starts and however long max_range_m (infinite
  // included); non-finite input gives nullopt.
  std::optional<double> cast_ray(const Eigen::Vector2d& from_m, double angle_rad, double max_range_m) const;
  // The same along a unit direction [cos, sin] (callers casting many rays rotate them once).
  std::optional<double> cast_ray_along(const Eigen::Vector2d& from_m, const Eigen::Vector2d& unit_direction,
                                       double max_range_m) const;

 private:
  std::size_t index(int ix, int iy) const { return static_cast<std::size_t>(iy) * width_ + ix; }
  Eigen::Vector2d origin_m_ = Eigen::Vector2d::Zero();
  double resolution_m_ = 0.1;
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint8_t> cells_;
};

}  // namespace beaconloc
