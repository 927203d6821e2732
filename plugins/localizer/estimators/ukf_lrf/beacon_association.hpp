#pragma once
// Data association of an anonymous beacon range, seed 001 Table 2: for every beacon B_j the
// predicted range's mean z_Bj and variance S_Bj over the sigma points (lines 1-5), then the
// beacon of maximum likelihood N(r; z_Bj, S_Bj) for the measured range r (lines 6-11).
#include <cstdint>
#include <optional>
#include <vector>

namespace beaconloc::ukf_lrf {

struct PredictedBeaconRange {
  std::uint32_t beacon_id;
  double mean_m;       // z_Bj (line 3)
  double variance_m2;  // S_Bj (line 4), the range noise included
};

// Lines 6-10: argmax_j det(2 pi S_Bj)^-1/2 exp(-(r - z_Bj)^2 / (2 S_Bj)); nullopt when there is
// no beacon or no variance is positive. Compared in log form (no underflow far from all).
std::optional<std::uint32_t> most_likely_beacon(double range_m,
                                                const std::vector<PredictedBeaconRange>& beacons);

}  // namespace beaconloc::ukf_lrf
