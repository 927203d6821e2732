// Discovery across hosts (issue 19): N localizer shards spread over three hosts made of network
// namespaces (tests/support/netns_hosts.hpp), finding each other by simple discovery
// (examples/qos/network.xml: multicast, every participant to every other) and, in turn in the
// same run, through two discovery servers (examples/qos/discovery_*.xml). For each:
// - found_s: from the first shard's start until a watcher on host 3 has every shard's
//   announcement (LocalizerShard): the last shard found by a participant that started first;
// - wire_kB, wire_packets: what the hosts put on the wire in the first --window-s seconds
//   (discovery, plus the shards' Diagnostics and liveliness, the same in both modes);
// - steady_kB_per_s: per second over the next --steady-s seconds (what discovery keeps costing
//   beside that same traffic).
// Needs root, iproute2 and fastdds-tools (scripts/install-deps.sh). One round per run: bench.sh
// repeats it and takes medians. Prints "metric value unit" lines; --csv appends them.
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.hpp"
#include "discovery_profiles.hpp"
#include "domain_id.hpp"
#include "netns_hosts.hpp"
#include "process.hpp"
#include "shard_watcher.hpp"

namespace beaconloc::bench {
namespace {

using Clock = std::chrono::steady_clock;
using testing::ChildProcess;
using testing::NetnsHosts;

enum class Mode { kSimple, kServers };
const char* name(Mode m) { return m == Mode::kSimple ? "simple" : "servers"; }

struct Setup {
  std::string dir;         // logs and profiles
  std::string simple_xml;  // network.xml as shipped
  std::string client_xml;  // discovery_client.xml with the hosts' addresses
  int domain_id = 0;
  double window_s = 10.0;
  double steady_s = 5.0;
};

struct Outcome {
  bool all_found = false;
  double found_s = 0.0;
  NetnsHosts::WireTotals window;
  double steady_kb_per_s = 0.0;
  std::string failure;
};

bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

Outcome run(Mode mode, int shards, const Setup& s, int round) {
  Outcome out;
  NetnsHosts hosts("bd" + std::to_string(::getpid()) + "r" + std::to_string(round), 3);
  const std::string tag = std::string(name(mode)) + "-" + std::to_string(shards);
  std::vector<std::unique_ptr<ChildProcess>> servers;
  if (mode == Mode::kServers) {
    for (int id = 0; id < 2; ++id) {
      const std::string xml = s.dir + "/server" + std::to_string(id) + ".xml";
      testing::write_text_file(xml, testing::discovery_server_profile(id));
      hosts.run_on(id + 1, [&] {
        servers.push_back(std::make_unique<ChildProcess>(
            std::vector<std::string>{testing::kDiscoveryServerProgram, "-x", xml},
            s.dir + "/" + tag + "-server" + std::to_string(id) + ".log"));
      });
      if (!wait_until([&] { return servers.back()->log().find("Server is running") != std::string::npos; },
                      std::chrono::seconds(10))) {
        out.failure = "discovery server " + std::to_string(id) + " did not start: " + servers.back()->log();
        return out;
      }
    }
  }
  const std::string profile = mode == Mode::kSimple ? "beaconloc.network" : "beaconloc.discovery_client";
  const std::string xml = mode == Mode::kSimple ? s.simple_xml : s.client_xml;
  hosts.enter(3);
  dds::DdsOptions dds;
  dds.domain_id = s.domain_id;
  dds.participant_profile = profile;
  dds.extra_qos_files = {xml};
  testing::ShardWatcher watcher(dds);
  const NetnsHosts::WireTotals before = hosts.sent();
  const Clock::time_point started = Clock::now();
  std::vector<std::unique_ptr<ChildProcess>> running;
  for (int i = 0; i < shards; ++i) {
    hosts.run_on(1 + i % 3, [&] {
      running.push_back(std::make_unique<ChildProcess>(
          std::vector<std::string>{BEACONLOC_EXECUTABLE, "localizer", "--shard", "--domain",
                                   std::to_string(s.domain_id), "--participant-profile", profile, "--qos",
                                   xml},
          s.dir + "/" + tag + "-shard" + std::to_string(i) + ".log"));
    });
  }
  out.all_found = wait_until([&] { return watcher.live().size() == static_cast<std::size_t>(shards); },
                             std::chrono::seconds(30));
  out.found_s = std::chrono::duration<double>(Clock::now() - started).count();
  if (!out.all_found) {
    out.failure =
        std::to_string(watcher.live().size()) + " of " + std::to_string(shards) + " shards found in 30 s";
  }
  std::this_thread::sleep_until(started + std::chrono::duration<double>(s.window_s));
  const NetnsHosts::WireTotals window_end = hosts.sent();
  out.window = {window_end.bytes - before.bytes, window_end.packets - before.packets};
  std::this_thread::sleep_for(std::chrono::duration<double>(s.steady_s));
  out.steady_kb_per_s = static_cast<double>(hosts.sent().bytes - window_end.bytes) / 1000.0 / s.steady_s;
  for (auto& p : running) p->signal(SIGTERM);
  for (auto& p : running) p->wait(std::chrono::seconds(15));
  for (auto& p : servers) p->signal(SIGINT);
  for (auto& p : servers) p->wait(std::chrono::seconds(10));
  return out;  // the watcher goes, then the hosts (its thread back home)
}

}  // namespace
}  // namespace beaconloc::bench

int main(int argc, char** argv) {
  using namespace beaconloc;
  using namespace beaconloc::bench;
  CLI::App app{"Discovery across namespace hosts: simple discovery against two discovery servers"};
  std::string shard_counts = "4 8 16";
  std::string csv;
  Setup s;
  app.add_option("--shards", shard_counts, "shard counts, e.g. \"4 8 16\"");
  app.add_option("--window-s", s.window_s, "seconds from the first start measured as discovery")
      ->check(CLI::PositiveNumber);
  app.add_option("--steady-s", s.steady_s, "seconds after the window measured as steady")
      ->check(CLI::PositiveNumber);
  app.add_option("--csv", csv, "append rows benchmark,case,metric,value,unit");
  CLI11_PARSE(app, argc, argv);
  if (const std::string why = testing::NetnsHosts::unavailable(); !why.empty()) {
    std::fprintf(stderr, "discovery benchmark: %s\n", why.c_str());
    return 2;
  }
  if (::access(testing::kDiscoveryServerProgram, X_OK) != 0) {
    std::fprintf(stderr, "discovery benchmark: %s not found (Debian's fastdds-tools)\n",
                 testing::kDiscoveryServerProgram);
    return 2;
  }
  char dir[] = "/tmp/beaconloc-discovery-XXXXXX";
  if (!::mkdtemp(dir)) return 2;
  s.dir = dir;
  s.simple_xml = s.dir + "/network.xml";
  s.client_xml = s.dir + "/discovery_client.xml";
  testing::write_text_file(s.simple_xml, testing::simple_network_profile());
  testing::write_text_file(s.client_xml, testing::discovery_client_profile());
  testing::DomainLease lease;
  s.domain_id = lease.id();
  int failures = 0, round = 0;
  std::istringstream counts(shard_counts);
  for (int shards = 0; counts >> shards;) {
    for (const Mode mode : {Mode::kSimple, Mode::kServers}) {
      const Outcome o = run(mode, shards, s, round++);
      if (!o.all_found) {
        // A run that found nothing is a failure with its reason, never a figure.
        std::fprintf(stderr, "discovery %s, %d shards: %s (logs in %s)\n", name(mode), shards,
                     o.failure.c_str(), dir);
        ++failures;
        continue;
      }
      Results r("discovery", std::string(name(mode)) + "_" + std::to_string(shards) + "_shards");
      r.add("found_s", o.found_s, "s");
      r.add("wire_kB", static_cast<double>(o.window.bytes) / 1000.0, "kB");
      r.add("wire_packets", static_cast<double>(o.window.packets), "packets");
      r.add("steady_kB_per_s", o.steady_kb_per_s, "kB/s");
      r.print();
      if (!csv.empty()) r.append_csv(csv);
    }
  }
  if (!failures) std::filesystem::remove_all(dir);
  return failures ? 1 : 0;
}
