#pragma once
// Accuracy against ground truth: seed 000 eq. 33-34 (E_p, E_phi) as RMS, mean and max.
#include <cstddef>

#include "beaconloc/core/pose2.hpp"

namespace beaconloc {

class PoseErrorAccumulator {
 public:
  void add(const Pose2& truth, const Pose2& estimate);
  std::size_t samples() const { return n_; }
  double position_rms_m() const;
  double position_mean_m() const;
  double position_max_m() const { return max_position_m_; }
  double heading_rms_deg() const;

 private:
  std::size_t n_ = 0;
  double sum_sq_position_ = 0.0;
  double sum_position_ = 0.0;
  double max_position_m_ = 0.0;
  double sum_sq_heading_ = 0.0;
};

}  // namespace beaconloc
