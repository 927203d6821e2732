#pragma once
// Time in the core: int64 nanoseconds of the source clock. The core never reads a clock.
#include <cmath>
#include <cstdint>

namespace beaconloc {

using StampNs = std::int64_t;
inline constexpr StampNs kNsPerSecond = 1'000'000'000;
inline constexpr StampNs kNsPerMillisecond = 1'000'000;

inline double ns_to_s(StampNs ns) { return static_cast<double>(ns) * 1e-9; }
inline StampNs s_to_ns(double s) { return static_cast<StampNs>(std::llround(s * 1e9)); }

}  // namespace beaconloc
