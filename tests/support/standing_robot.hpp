#pragma once
// A robot standing still at a known pose under beacons, for tests that drive an estimator by
// hand: each 200 ms slot one beacon fires (exact ranges to every receiver), then 20 odometry
// samples 10 ms apart.
#include "beaconloc/core/estimator.hpp"
#include "exact_ranges.hpp"

namespace beaconloc::test_support {

inline void standing_slot(Estimator& estimator, const Pose2& pose_map_base, const ReceiverArray& receivers,
                          const Beacon& beacon, StampNs& stamp_ns, bool with_odometry = true) {
  for (const auto& r : exact_ranges(pose_map_base, receivers, beacon, stamp_ns)) estimator.update(r);
  for (int k = 0; k < 20; ++k) {
    stamp_ns += 10'000'000;
    OdometrySample o;
    o.stamp_ns = stamp_ns;
    o.wheel_base_m = 0.33;
    if (with_odometry) estimator.predict(o);
  }
}

}  // namespace beaconloc::test_support
