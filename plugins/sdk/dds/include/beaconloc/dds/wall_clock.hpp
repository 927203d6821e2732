#pragma once
// The participants' clocks (never the core's), in int64 ns: system time for stamping live data,
// the steady clock for how long something has been silent.
#include <chrono>

#include "beaconloc/core/time.hpp"

namespace beaconloc::dds {

inline StampNs wall_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

inline StampNs steady_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace beaconloc::dds
