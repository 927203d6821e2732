#pragma once
// Hosts made of Linux network namespaces on this machine, for tests of what crosses a network
// (issue 19): a hub namespace holding a bridge, and each host a namespace of its own with its
// loopback and one veth to the hub, at 10.88.0.<host>/24. Nothing leaves the machine: the bridge
// has no uplink and no host has a route off its subnet. Needs root and iproute2's `ip`.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace beaconloc::testing {

class NetnsHosts {
 public:
  // Why hosts cannot be made here ("" when they can): not root, no `ip`.
  static std::string unavailable();
  // Creates hosts 1..count, their namespaces named <prefix>h<i> (the prefix unique to the run);
  // throws std::runtime_error with the command that failed (what it made so far is removed).
  NetnsHosts(const std::string& prefix, int count);
  ~NetnsHosts();  // the calling thread back in its own namespace; the namespaces deleted
  NetnsHosts(const NetnsHosts&) = delete;
  NetnsHosts& operator=(const NetnsHosts&) = delete;

  static std::string address(int host) { return "10.88.0." + std::to_string(host); }
  // Moves the calling thread into the host's network namespace: the sockets it opens, the threads
  // and the processes it starts from then on are the host's (a DDS participant created next, a
  // child started with ChildProcess). Throws std::runtime_error when it cannot.
  void enter(int host);
  // Runs fn on a thread of its own inside the host (the processes it starts are the host's) and
  // waits for it, rethrowing what it threw: the calling thread stays where it is.
  void run_on(int host, const std::function<void()>& fn);

  struct WireTotals {
    std::uint64_t bytes = 0;  // Ethernet frames, headers included
    std::uint64_t packets = 0;
  };
  // What the hosts have put on the wire so far: the frames the hub received from every host's
  // veth (a multicast frame counts once, however many hosts the bridge floods it to).
  WireTotals sent();

 private:
  void ip(const std::vector<std::string>& args);  // `ip ARGS`, throws naming it when it fails
  void remove();

  std::string prefix_;
  int count_ = 0;
  std::vector<std::string> made_;  // namespaces created, in order
  int home_fd_ = -1;               // the namespace the creating thread came from
};

}  // namespace beaconloc::testing
