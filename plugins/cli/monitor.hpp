#pragma once
// `beaconloc monitor`: the poses on the bus each second (one line per robot), the participants
// whose health or liveness changed, and at the end every participant's counts, the robots served
// by two localizers at once, and with a truth file the accuracy.
#include <string>

#include "beaconloc/dds/participant.hpp"

namespace beaconloc::cli {

struct MonitorOptions {
  dds::DdsOptions dds;
  double duration_s = 0.0;  // 0: until stopped
  std::string truth_file;   // score the poses against it at the end
  std::string out_file;     // write every pose to this CSV at the end
  // Every second, the fleet view (fleet_view.hpp: a row per robot with its status, pose rate,
  // age, rejections and the localizer serving it) instead of a pose line per robot.
  bool fleet = false;
};

// The exit code: 1 when a truth file was given and no pose came to score.
int run_monitor(const MonitorOptions& options);

}  // namespace beaconloc::cli
