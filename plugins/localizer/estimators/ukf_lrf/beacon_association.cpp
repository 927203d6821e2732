#include "beacon_association.hpp"

#include <cmath>
#include <limits>

namespace beaconloc::ukf_lrf {

std::optional<std::uint32_t> most_likely_beacon(double r, const std::vector<PredictedBeaconRange>& beacons) {
  std::optional<std::uint32_t> best;
  double best_log_likelihood = -std::numeric_limits<double>::infinity();
  for (const auto& b : beacons) {
    if (!(b.variance_m2 > 0.0)) continue;
    const double e = r - b.mean_m;
    const double log_likelihood = -0.5 * std::log(2.0 * M_PI * b.variance_m2) - 0.5 * e * e / b.variance_m2;
    if (log_likelihood > best_log_likelihood) {
      best_log_likelihood = log_likelihood;
      best = b.beacon_id;
    }
  }
  return best;
}

}  // namespace beaconloc::ukf_lrf
