#include "beaconloc/core/pose_error.hpp"

#include <algorithm>
#include <cmath>

namespace beaconloc {

void PoseErrorAccumulator::add(const Pose2& truth, const Pose2& estimate) {
  const double e_p = (truth.head<2>() - estimate.head<2>()).norm();  // eq. 33
  const double e_phi = wrap_angle_rad(truth.z() - estimate.z());     // eq. 34
  ++n_;
  sum_sq_position_ += e_p * e_p;
  sum_position_ += e_p;
  max_position_m_ = std::max(max_position_m_, e_p);
  sum_sq_heading_ += e_phi * e_phi;
}

double PoseErrorAccumulator::position_rms_m() const {
  return n_ ? std::sqrt(sum_sq_position_ / static_cast<double>(n_)) : 0.0;
}
double PoseErrorAccumulator::position_mean_m() const {
  return n_ ? sum_position_ / static_cast<double>(n_) : 0.0;
}
double PoseErrorAccumulator::heading_rms_deg() const {
  return n_ ? std::sqrt(sum_sq_heading_ / static_cast<double>(n_)) * 180.0 / M_PI : 0.0;
}

}  // namespace beaconloc
