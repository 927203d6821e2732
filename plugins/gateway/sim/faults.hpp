#pragma once
// Faults a simulated world can be given, to test that the pipeline survives them: a beacon that
// dies, TOF outages (the gateway stops publishing TOFs while odometry goes on), and echoes (the
// first arrival is a reflection: EchoModel). Given as text on the command line (--fault of
// gateway, run and accuracy):
//   beacon_dies=ID@T     beacon ID fires no more from T seconds of source time on
//   tof_outage=FROM:TO   no TOF is published from FROM to TO seconds of source time
//   echoes=P             each TOF is an echo with probability P (extra path as the scenario's echo)
#include <string>

#include "scenario.hpp"

namespace beaconloc::sim {

// Applies one fault to the scenario. Throws std::invalid_argument naming the text when it is not
// one of the forms above, names a beacon the scenario does not have, or has values out of range.
void apply_fault(Scenario& scenario, const std::string& spec);

}  // namespace beaconloc::sim
