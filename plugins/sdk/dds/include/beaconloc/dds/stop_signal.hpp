#pragma once
// Clean stop on SIGINT, SIGTERM, SIGHUP and SIGPIPE: the handler only sets a flag; loops poll it.
#include <chrono>

namespace beaconloc::dds {

void install_stop_handlers();
bool stop_requested();
void request_stop();
// Sleeps until a stop is requested or the timeout passes; returns stop_requested().
bool wait_for_stop(std::chrono::milliseconds timeout);

}  // namespace beaconloc::dds
