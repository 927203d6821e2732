#pragma once
// The raw Fast DDS hop: this process and a copy of itself (--role echo) ping-pong a RawTof on
// topics with raw_tof's QoS profiles; hop = round trip / 2.
#include <cstddef>
#include <string>
#include <vector>

#include "common.hpp"

namespace beaconloc::latency {

struct HopResult {
  std::vector<double> hop_us;      // round trip / 2, one round trip per --hop-period-ms
  std::vector<double> b2b_hop_us;  // round trip / 2, each ping right after the previous pong
  std::size_t sent = 0;
  std::size_t lost = 0;      // no pong within 1 s
  double echo_cpu_s = 0.0;  // the echo's CPU time over the paced, measured round trips (sent)
};

// The echo peer (--role echo): writes back every ping as a pong until a stop signal. Returns 0.
// keystore: DDS Security on (Transport::keystore).
int run_echo(int domain, const std::string& profile, const std::string& keystore);

// Starts the echo peer on st.hop_domain and measures: until it answers, probes; then 1 s unmeasured
// and st.hop_duration_s measured at one round trip per st.hop_period_ms; then st.b2b_hop_s of
// back-to-back round trips.
HopResult run_hop(const Settings& st, const Transport& t);

}  // namespace beaconloc::latency
