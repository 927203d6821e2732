#pragma once
// Noise-free ranges from one beacon to every receiver of a robot at a known pose, for tests and
// benchmarks that need a filter fed with exact geometry.
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "beaconloc/core/receiver_array.hpp"

namespace beaconloc::test_support {

inline std::vector<RangeMeasurement> exact_ranges(const Pose2& pose_map_base, const ReceiverArray& receivers,
                                                  const Beacon& beacon, StampNs stamp_ns,
                                                  double variance_m2 = 1e-4) {
  std::vector<RangeMeasurement> out;
  for (std::size_t l = 0; l < receivers.size(); ++l) {
    RangeMeasurement r;
    r.stamp_ns = stamp_ns;
    r.beacon_id = beacon.id;
    r.receiver_id = static_cast<std::uint32_t>(l);
    r.range_m = predict_range(pose_map_base, receivers.receivers_base_m[l], receivers.receiver_height_m,
                              beacon.position_map_m)
                    .range_m;
    r.variance_m2 = variance_m2;
    out.push_back(r);
  }
  return out;
}

}  // namespace beaconloc::test_support
