#pragma once
// The participants' clock (never the core's): system time in int64 ns, for stamping live data.
#include <chrono>

#include "beaconloc/core/time.hpp"

namespace beaconloc::dds {

inline StampNs wall_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace beaconloc::dds
