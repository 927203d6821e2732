#pragma once
// Time in the core: int64 nanoseconds of the source clock. The core never reads a clock.
#include <cmath>
#include <cstdint>

namespace beaconloc {

using StampNs = std::int64_t;
inline constexpr StampNs kNsPerSecond = 1'000'000'000;
inline constexpr StampNs kNsPerMillisecond = 1'000'000;

// stamp < newest - age (age >= 0) for any two stamps the wire can carry: the subtraction is
// done without overflowing near the ends of the clock.
inline bool older_than(StampNs stamp, StampNs newest, StampNs age) {
  if (stamp >= newest) return false;
  return static_cast<std::uint64_t>(newest) - static_cast<std::uint64_t>(stamp) >
         static_cast<std::uint64_t>(age);
}

inline double ns_to_s(StampNs ns) { return static_cast<double>(ns) * 1e-9; }
inline StampNs s_to_ns(double s) { return static_cast<StampNs>(std::llround(s * 1e9)); }

}  // namespace beaconloc
