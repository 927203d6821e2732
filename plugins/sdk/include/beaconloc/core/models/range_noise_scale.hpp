#pragma once
// Noise that learns its scale (issue 18, item 3): a ranging sensor's noise is rarely what its
// datasheet (or a user) declares, and it changes with the site. The true sigma is learnt online
// as k times the declared one, k tracked so that half the innovations fall within 0.6745 of
// their predicted sigma (the median of |N(0, 1)|): each range moves log k up by step / 2 when
// its innovation is outside, down by step / 2 when inside (a Robbins-Monro quantile tracker;
// constant step: it follows a sensor whose noise changes as the robot moves). A median, not a
// variance: multipath, echoes and lost line of sight (the tails) each count as one vote, so they
// do not inflate k; they are left to the filter's gate, which sees the learnt k.
// Pure maths: no DDS, no clock.

#include <cstdint>

namespace beaconloc {

class RangeNoiseScale {
 public:
  // Each range moves log k by step / 2, up or down (0.02: 18 ranges that all agree move k by a
  // fifth); k stays within [min_scale, max_scale].
  explicit RangeNoiseScale(double step = 0.02, double min_scale = 0.25, double max_scale = 4.0);
  // The variance to fuse a range of this declared variance with.
  double variance_m2(double declared_m2) const { return scale() * scale() * declared_m2; }
  double scale() const;
  // One range's innovation (measured minus predicted), the state's share of its variance
  // (H P H^T) and its declared variance. A non-finite one is not learnt from.
  void learn(double innovation_m, double state_m2, double declared_m2);
  std::uint64_t ranges_learnt() const { return ranges_; }

 private:
  double step_;
  double min_log_scale_;
  double max_log_scale_;
  double log_scale_ = 0.0;
  std::uint64_t ranges_ = 0;
};

}  // namespace beaconloc
