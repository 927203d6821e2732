#include "discovery_profiles.hpp"

#include <fstream>
#include <iterator>
#include <regex>
#include <stdexcept>

#include "netns_hosts.hpp"

namespace beaconloc::testing {
namespace {
std::string example(const std::string& name) {
  const std::string path = std::string(BEACONLOC_SOURCE_DIR) + "/examples/qos/" + name;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
// The examples' server addresses.
const std::regex kServer0Address("192\\.168\\.1\\.10");
const std::regex kServer1Address("192\\.168\\.1\\.11");
}  // namespace

std::string discovery_client_profile() {
  const std::string xml =
      std::regex_replace(example("discovery_client.xml"), kServer0Address, NetnsHosts::address(1));
  return std::regex_replace(xml, kServer1Address, NetnsHosts::address(2));
}

std::string discovery_server_profile(int id) {
  const std::string xml =
      std::regex_replace(example("discovery_server.xml"), kServer0Address, NetnsHosts::address(id + 1));
  // The prefix fast-discovery-server gives server id `id`: its third octet.
  return std::regex_replace(xml, std::regex("44\\.53\\.00\\."), "44.53.0" + std::to_string(id) + ".");
}

std::string simple_network_profile() { return example("network.xml"); }

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path);
}

}  // namespace beaconloc::testing
