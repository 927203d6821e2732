#pragma once
// The fleet benchmark's feeder (--role feeder): the samples of N robots, as N simulated gateways
// would write them, from one process: the beacon map, 100 Hz odometry and 15 TOF/s per robot
// (3 receivers x 5 Hz slots), on the wall clock, with the writer profiles of
// fleet_feeder_qos.xml.
#include <string>

#include "beaconloc/dds/participant.hpp"

namespace beaconloc::bench {

std::string robot_name(int i);  // "robot-<i>"
// Writes for `seconds` of wall time; prints "feeder written=W failed=F late_ms=L" (the most it
// fell behind the wall clock). 0 when every write succeeded.
int run_feeder(const dds::DdsOptions& dds, int robots, double seconds);

}  // namespace beaconloc::bench
