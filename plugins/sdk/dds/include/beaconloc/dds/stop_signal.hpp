#pragma once
// Clean stop on SIGINT, SIGTERM, SIGHUP and SIGPIPE: the handler only sets a flag; loops poll it.
// The same SIGINT or SIGTERM a second time, while the clean stop is under way (or stuck), ends
// the process at once with status 128 + the signal's number, saying so on stderr.
#include <chrono>

namespace beaconloc::dds {

void install_stop_handlers();
bool stop_requested();
void request_stop();
// Sleeps until a stop is requested or the timeout passes; returns stop_requested().
bool wait_for_stop(std::chrono::milliseconds timeout);

}  // namespace beaconloc::dds
