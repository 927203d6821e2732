#include "netns_hosts.hpp"

#include <fcntl.h>
#include <sched.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <regex>
#include <stdexcept>
#include <thread>

#include "process.hpp"

namespace beaconloc::testing {
namespace {
constexpr const char* kIp = "/usr/sbin/ip";

void enter_namespace(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  const int rc = ::setns(fd, CLONE_NEWNET);
  const int error = errno;
  ::close(fd);
  if (rc != 0) throw std::runtime_error("setns " + path + ": " + std::strerror(error));
}
}  // namespace

std::string NetnsHosts::unavailable() {
  if (::geteuid() != 0) return "network namespaces need root";
  if (::access(kIp, X_OK) != 0) return std::string(kIp) + " not found (Debian's iproute2)";
  return "";
}

NetnsHosts::NetnsHosts(const std::string& prefix, int count) : prefix_(prefix), count_(count) {
  home_fd_ = ::open("/proc/thread-self/ns/net", O_RDONLY | O_CLOEXEC);
  if (home_fd_ < 0)
    throw std::runtime_error(std::string("cannot open this thread's namespace: ") + std::strerror(errno));
  try {
    const std::string hub = prefix_ + "hub";
    ip({"netns", "add", hub});
    made_.push_back(hub);
    ip({"-n", hub, "link", "add", "br0", "type", "bridge"});
    ip({"-n", hub, "link", "set", "br0", "up"});
    for (int i = 1; i <= count_; ++i) {
      const std::string host = prefix_ + "h" + std::to_string(i);
      const std::string veth = "vh" + std::to_string(i);
      ip({"netns", "add", host});
      made_.push_back(host);
      ip({"-n", hub, "link", "add", veth, "type", "veth", "peer", "name", "eth0", "netns", host});
      ip({"-n", hub, "link", "set", veth, "master", "br0"});
      ip({"-n", hub, "link", "set", veth, "up"});
      ip({"-n", host, "addr", "add", address(i) + "/24", "dev", "eth0"});
      ip({"-n", host, "link", "set", "eth0", "up"});
      ip({"-n", host, "link", "set", "lo", "up"});
    }
  } catch (...) {
    remove();
    throw;
  }
}

NetnsHosts::~NetnsHosts() { remove(); }

void NetnsHosts::remove() {
  if (home_fd_ >= 0) {
    ::setns(home_fd_, CLONE_NEWNET);  // out of any host before they go
    ::close(home_fd_);
    home_fd_ = -1;
  }
  for (auto it = made_.rbegin(); it != made_.rend(); ++it) {
    run_command({kIp, "netns", "delete", *it}, std::chrono::seconds(10));  // its veth and bridge go with it
  }
  made_.clear();
}

void NetnsHosts::enter(int host) {
  enter_namespace("/var/run/netns/" + prefix_ + "h" + std::to_string(host));
}

void NetnsHosts::run_on(int host, const std::function<void()>& fn) {
  std::exception_ptr error;
  std::thread([&] {
    try {
      enter(host);
      fn();
    } catch (...) {
      error = std::current_exception();
    }
  }).join();
  if (error) std::rethrow_exception(error);
}

NetnsHosts::WireTotals NetnsHosts::sent() {
  const auto [code, json] =
      run_command({kIp, "-n", prefix_ + "hub", "-s", "-j", "link", "show"}, std::chrono::seconds(10));
  if (code != 0) throw std::runtime_error("ip -s link in the hub failed: " + json);
  // Each hub end of a host's veth (vh<i>), its received counters: the first "rx" after its name.
  static const std::regex kHostEnd(
      "\"ifname\":\"vh[0-9]+\".*?\"rx\":\\{\"bytes\":([0-9]+),\"packets\":([0-9]+)");
  WireTotals totals;
  int ends = 0;
  for (auto it = std::sregex_iterator(json.begin(), json.end(), kHostEnd); it != std::sregex_iterator();
       ++it, ++ends) {
    totals.bytes += std::stoull((*it)[1]);
    totals.packets += std::stoull((*it)[2]);
  }
  if (ends != count_)
    throw std::runtime_error("ip -s link in the hub: " + std::to_string(ends) + " host ends of " +
                             std::to_string(count_));
  return totals;
}

void NetnsHosts::ip(const std::vector<std::string>& args) {
  std::vector<std::string> argv{kIp};
  argv.insert(argv.end(), args.begin(), args.end());
  const auto [code, output] = run_command(argv, std::chrono::seconds(10));
  if (code != 0) {
    std::string command;
    for (const std::string& a : argv) command += (command.empty() ? "" : " ") + a;
    throw std::runtime_error(command + " failed (" + std::to_string(code) + "): " + output);
  }
}

}  // namespace beaconloc::testing
