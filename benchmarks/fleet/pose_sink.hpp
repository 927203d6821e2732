#pragma once
// The fleet benchmark's pose sink (--role sink), standing in for the robots' controllers: counts,
// in the window [from_ns, to_ns] of pose stamps, the odometry poses of each robot (the first
// pose at a stamp; a correction repeats the stamp) and the age of every pose on arrival.
#include "beaconloc/core/time.hpp"
#include "beaconloc/dds/participant.hpp"

namespace beaconloc::bench {

// Runs until SIGINT or SIGTERM, then prints "sink poses=P corrections=C robots=R
// age_p50_ms=.. age_p99_ms=.. age_max_ms=..".
int run_sink(const dds::DdsOptions& dds, StampNs from_ns, StampNs to_ns);

}  // namespace beaconloc::bench
