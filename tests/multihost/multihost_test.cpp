// Past one machine (issue 19): three hosts made of network namespaces with veth pairs (their own
// addresses; nothing leaves the machine), participants that find each other through two
// redundant Fast DDS discovery servers (examples/qos/discovery_*.xml, as shipped but for the
// addresses), and localizer shards on two hosts serving robots whose gateways run on a third:
// every robot localized; one server killed and a shard started afterwards still found; a shard
// killed and its robots served again within 2 s. Needs root and iproute2 (skipped otherwise; CI
// runs as root).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "discovery_profiles.hpp"
#include "netns_hosts.hpp"
#include "participants_test.hpp"
#include "process.hpp"
#include "shard_watch.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class MultiHost : public ParticipantsTest {
 protected:
  MultiHost() : ParticipantsTest("beaconloc.discovery_client") {}
  void SetUp() override {
    ParticipantsTest::SetUp();
    if (const std::string why = NetnsHosts::unavailable(); !why.empty()) GTEST_SKIP() << why;
    if (::access(kDiscoveryServerProgram, X_OK) != 0)
      GTEST_SKIP() << kDiscoveryServerProgram << " not found (Debian's fastdds-tools)";
    client_xml_ = path("discovery_client.xml");
    write_text_file(client_xml_, discovery_client_profile());
    dds_.extra_qos_files = {client_xml_};
    hosts_ = std::make_unique<NetnsHosts>("bl" + std::to_string(::getpid()), 3);
  }
  void TearDown() override {
    hosts_.reset();
    ParticipantsTest::TearDown();
  }
  // `beaconloc <sub>` as a client of the two servers, on a host.
  std::unique_ptr<ChildProcess> start_on(int host, const std::string& sub,
                                         const std::vector<std::string>& extra, const std::string& log) {
    std::vector<std::string> args{"--qos", client_xml_};
    args.insert(args.end(), extra.begin(), extra.end());
    std::unique_ptr<ChildProcess> child;
    hosts_->run_on(host, [&] { child = std::make_unique<ChildProcess>(command(sub, args), path(log)); });
    return child;
  }
  // Discovery server `id` (0 or 1) on host id + 1, once it says it runs.
  std::unique_ptr<ChildProcess> start_server(int id) {
    const std::string xml = path("discovery_server_" + std::to_string(id) + ".xml");
    write_text_file(xml, discovery_server_profile(id));
    std::unique_ptr<ChildProcess> server;
    hosts_->run_on(id + 1, [&] {
      server = std::make_unique<ChildProcess>(std::vector<std::string>{kDiscoveryServerProgram, "-x", xml},
                                              path("discovery_server_" + std::to_string(id) + ".log"));
    });
    EXPECT_TRUE(eventually([&] { return server->log().find("Server is running") != std::string::npos; }, 10s))
        << server->log();
    return server;
  }

  std::string client_xml_;
  std::unique_ptr<NetnsHosts> hosts_;
};

TEST_F(MultiHost, ShardsOnTwoHostsServeAThirdsRobotsThroughTwoDiscoveryServers) {
  const std::vector<std::string> robots{"robot-1", "robot-2", "robot-3", "robot-4"};
  auto server0 = start_server(0);
  auto server1 = start_server(1);
  // The test watches from host 3, as a client of both servers.
  hosts_->enter(3);
  PoseRecorder poses(dds_);
  ShardWatcher shards(dds_);

  const Clock::time_point started = Clock::now();
  std::vector<std::unique_ptr<ChildProcess>> on_host1;
  for (const std::string& robot : robots) {
    on_host1.push_back(
        start_on(1, "gateway", {"--robot", robot, "--duration-s", "0"}, "gateway-" + robot + ".log"));
  }
  on_host1.push_back(start_on(1, "decoder", {}, "decoder.log"));
  std::map<std::string, std::unique_ptr<ChildProcess>> running;
  auto shard_on = [&](int host, const std::string& name) {
    return [this, host, name] { return start_on(host, "localizer", {"--shard"}, name + ".log"); };
  };
  start_shard(shards, shard_on(2, "shard-a"), running);
  start_shard(shards, shard_on(3, "shard-b"), running);
  ASSERT_EQ(shards.live().size(), 2u);
  auto owners = expected_owners(shards.live(), robots);
  ASSERT_TRUE(eventually([&] { return served_as_assigned(poses, owners); }, 30s))
      << running.begin()->second->log();
  std::printf(
      "across hosts: %zu robots on host 1 localized by shards on hosts 2 and 3, %.2f s after the start\n",
      robots.size(), std::chrono::duration<double>(Clock::now() - started).count());

  // Server 0 killed: a shard started afterwards (on host 1, beside the dead server) is found, and
  // finds the others, through server 1 alone.
  server0->signal(SIGKILL);
  server0->wait(10s);
  const Clock::time_point joined = Clock::now();
  const std::string shard_c = start_shard_with_a_share(shards, shard_on(1, "shard-c"), running, robots);
  ASSERT_FALSE(shard_c.empty()) << "a shard started with one server down was never found";
  ASSERT_EQ(shards.live().size(), 3u);
  owners = expected_owners(shards.live(), robots);
  EXPECT_TRUE(eventually([&] { return served_as_assigned(poses, owners); }, 30s)) << running[shard_c]->log();
  std::map<std::string, int> share;
  for (const auto& [robot, owner] : owners) ++share[owner];
  std::printf(
      "server 0 killed: a shard started after it was found and serves its share (%d of %zu robots) "
      "%.2f s after its start\n",
      share[shard_c], robots.size(), std::chrono::duration<double>(Clock::now() - joined).count());

  // The shard serving the most robots killed: the two others take its robots over.
  std::string victim = share.begin()->first;
  for (const auto& [id, n] : share) {
    if (n > share[victim]) victim = id;
  }
  std::set<std::string> left;
  for (const std::string& s : shards.live()) {
    if (dds::participant_of_writer(s) != victim) left.insert(s);
  }
  std::vector<std::string> taken_over;
  for (const auto& [robot, owner] : owners) {
    if (owner == victim) taken_over.push_back(robot);
  }
  const Clock::time_point killed = Clock::now();
  running[victim]->signal(SIGKILL);
  running[victim]->wait(10s);
  running.erase(victim);
  expect_taken_over_within_2s(poses, taken_over, expected_owners(left, robots), killed);

  expect_no_double_serving(poses, killed);
  for (auto& [id, shard] : running) stop_cleanly(*shard, "shard");
  for (auto& p : on_host1) stop_cleanly(*p, "host 1 participant");
  server1->signal(SIGINT);  // not ours: how it stops is its own business
  EXPECT_TRUE(server1->wait(10s)) << "discovery server 1 did not stop on SIGINT";
}

}  // namespace
}  // namespace beaconloc::testing
