#pragma once
// The laser measurement model of seed 001 (h for the LRF in eq. 16): the range each beam would
// measure from a robot pose, by ray casting on the occupancy grid (10 cm cells, Sec. 4.1).
#include <cmath>
#include <memory>
#include <vector>

#include "beaconloc/core/models/model_concepts.hpp"
#include "beaconloc/core/occupancy_grid.hpp"
#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

struct LaserBeams {
  Pose2 mount_base = Pose2::Zero();  // the scanner's pose on the robot
  double max_range_m = 80.0;         // what a beam that hits nothing reads
  // Each beam's unit direction in the scanner frame.
  std::vector<Eigen::Vector2d> directions;
  void add_beam(double angle_rad) { directions.emplace_back(std::cos(angle_rad), std::sin(angle_rad)); }
  std::size_t size() const { return directions.size(); }
};

// Expected range of every beam from the robot pose pose_map_base; a beam that meets no
// occupied cell within max_range_m reads max_range_m.
void expected_laser_ranges(const OccupancyGrid& grid, const Pose2& pose_map_base, const LaserBeams& beams,
                           double* ranges_out);

// The beams of one scan as a measurement model (core/models/model_concepts.hpp) on any state
// holding the pose. A ray cast has no useful derivative (it jumps at every cell edge): the model
// has no Jacobian, and only the UKF takes it (kHasJacobian = false). A model of no beams casts
// no ray (and needs no grid).
class LaserBeamModel : public PredictsByWritingInPlace<LaserBeamModel> {
 public:
  static constexpr int kSize = Eigen::Dynamic;
  static constexpr bool kHasJacobian = false;
  static constexpr bool kPlainResidual = true;  // z - h: no angle in z
  using Vector = Eigen::VectorXd;

  LaserBeamModel(std::shared_ptr<const OccupancyGrid> grid, LaserBeams beams, double beam_variance_m2,
                 PoseIndex pose = {})
      : grid_(std::move(grid)), beams_(std::move(beams)), variance_m2_(beam_variance_m2), pose_(pose) {}

  Eigen::Index size() const { return static_cast<Eigen::Index>(beams_.size()); }
  template <int N>
  void predict_into(const Vec<N>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    if (size() > 0) expected_laser_ranges(*grid_, pose_.pose_of(x), beams_, out.data());
  }
  Eigen::MatrixXd noise() const { return variance_m2_ * Eigen::MatrixXd::Identity(size(), size()); }
  void noise_into(Eigen::Ref<Eigen::MatrixXd> r) const { r.diagonal().setConstant(variance_m2_); }
  Vector residual(const Vector& z, const Vector& h) const { return z - h; }

 private:
  std::shared_ptr<const OccupancyGrid> grid_;
  LaserBeams beams_;
  double variance_m2_;
  PoseIndex pose_;
};

}  // namespace beaconloc
