#pragma once
// The shipped profiles for hosts on a network (examples/qos/discovery_*.xml, network.xml), made
// ready for the namespace hosts of NetnsHosts: discovery server 0 on host 1, server 1 on host 2.
// The multi-host test and the discovery benchmark run them as shipped but for the addresses.
#include <string>

namespace beaconloc::testing {

inline constexpr const char* kDiscoveryServerProgram = "/usr/bin/fast-discovery-server";  // fastdds-tools

// discovery_client.xml (profile beaconloc.discovery_client) with the servers' host addresses.
std::string discovery_client_profile();
// discovery_server.xml for server id 0 or 1, listening on host id + 1.
std::string discovery_server_profile(int id);
// network.xml (profile beaconloc.network: simple discovery, multicast) as shipped.
std::string simple_network_profile();

// Writes text to path; throws std::runtime_error when it cannot.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace beaconloc::testing
