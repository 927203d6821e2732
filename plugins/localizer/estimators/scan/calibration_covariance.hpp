#pragma once
// The covariance of a calibrated beacon's map position (Sec. 3.5, eq. 42-43 carry no covariance:
// ours). The transform maps the group's frame onto the global frame's track over the overlap, so
// the global frame's error at the pairs moves every beacon: its position error as it is, and its
// heading error turned about the pair, a lever arm of up to 5 m to the beacon. Averaged over
// the pairs: C(b) = mean_i J_i P_i J_i^T, J_i = [I2 | perp(b - p_i)], perp(d) = (-d_y, d_x),
// with P_i the global frame's (x, y, yaw) covariance at pair i and p_i its position there.
#include <Eigen/Core>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc::scan {

class CalibrationCovariance {
 public:
  // A pair's global position and the global frame's covariance there.
  void add(const Eigen::Vector2d& global_m, const Cov3& covariance) {
    const Eigen::Vector2d q = perp(global_m);
    const Eigen::Matrix2d a = covariance.topLeftCorner<2, 2>();
    const Eigen::Vector2d c = covariance.block<2, 1>(0, 2);
    const double v = covariance(2, 2);
    sum_a_ += a;
    sum_c_ += c;
    sum_cq_ += c * q.transpose();
    sum_v_ += v;
    sum_vq_ += v * q;
    sum_vqq_ += v * q * q.transpose();
    ++pairs_;
  }
  std::size_t pairs() const { return pairs_; }
  void clear() { *this = CalibrationCovariance(); }

  // The mean over the pairs of J_i P_i J_i^T for a beacon at b_m; zero before any pair. With
  // d_i = b - p_i, perp(d_i) = B - q_i (B = perp(b), q_i = perp(p_i)), expanded in the sums.
  Eigen::Matrix2d at(const Eigen::Vector2d& b_m) const {
    if (pairs_ == 0) return Eigen::Matrix2d::Zero();
    const Eigen::Vector2d bp = perp(b_m);
    const Eigen::Matrix2d cross = sum_c_ * bp.transpose() - sum_cq_;  // sum_i c_i (B - q_i)^T
    const Eigen::Matrix2d lever = sum_v_ * bp * bp.transpose() - bp * sum_vq_.transpose() -
                                  sum_vq_ * bp.transpose() + sum_vqq_;  // sum_i v_i (B - q_i)(B - q_i)^T
    const Eigen::Matrix2d c = (sum_a_ + cross + cross.transpose() + lever) / static_cast<double>(pairs_);
    return 0.5 * (c + c.transpose());
  }

 private:
  static Eigen::Vector2d perp(const Eigen::Vector2d& d) { return {-d.y(), d.x()}; }
  Eigen::Matrix2d sum_a_ = Eigen::Matrix2d::Zero();
  Eigen::Vector2d sum_c_ = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sum_cq_ = Eigen::Matrix2d::Zero();
  double sum_v_ = 0.0;
  Eigen::Vector2d sum_vq_ = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sum_vqq_ = Eigen::Matrix2d::Zero();
  std::size_t pairs_ = 0;
};

}  // namespace beaconloc::scan
