// Localizer shards (issue 19): `beaconloc localizer --shard` processes share the robots among the
// live ones with no coordinator (rendezvous hashing on their announcement writers' ids); a shard
// stalled past its lease or killed has its robots served again by the others within 2 s,
// re-localized from the beacons, and one back from a stall takes them again; a shard started
// later takes its share without a restart of the others; the fleet view names the shard serving
// each robot. Never two shards' poses of one robot at once.
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "participants_test.hpp"
#include "process.hpp"
#include "shard_watch.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

class Shards : public ParticipantsTest {
 protected:
  // UDP on loopback alone: a shard killed with SIGKILL cannot remove shared-memory files.
  Shards() : ParticipantsTest("beaconloc.loopback_udp") {}
};

TEST_F(Shards, ShareTheRobotsTakeOverADeadShardsAndGiveANewShardItsShare) {
  const std::vector<std::string> robots{"robot-1", "robot-2", "robot-3", "robot-4"};
  PoseRecorder poses(dds_);
  ShardWatcher shards(dds_);
  std::vector<std::unique_ptr<ChildProcess>> gateways;
  for (const std::string& robot : robots) {
    gateways.push_back(std::make_unique<ChildProcess>(
        command("gateway", {"--robot", robot, "--duration-s", "0"}), path("gateway-" + robot + ".log")));
  }
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  // Shards by their participant id (the announcement's writer's prefix).
  std::map<std::string, std::unique_ptr<ChildProcess>> running;
  auto shard_process = [&](const std::string& name) {
    return [this, name] {
      return std::make_unique<ChildProcess>(command("localizer", {"--shard"}), path(name + ".log"));
    };
  };
  start_shard(shards, shard_process("shard-a"), running);
  start_shard(shards, shard_process("shard-b"), running);
  ASSERT_EQ(shards.live().size(), 2u);

  // Every robot served, each by the shard the assignment gives it.
  auto owners = expected_owners(shards.live(), robots);
  ASSERT_TRUE(eventually([&] { return served_as_assigned(poses, owners); }, 30s))
      << running.begin()->second->log();
  std::map<std::string, int> share;
  for (const auto& [robot, owner] : owners) ++share[owner];
  std::printf("two shards: %d and %d of %zu robots\n", share[running.begin()->first],
              share[std::next(running.begin())->first], robots.size());

  // The shard serving the most robots stalls past its lease (SIGSTOP until its robots are taken
  // over, about 1 s): the other one
  // takes its robots over; back, it takes them again, afresh, never serving one at the same time.
  const std::string victim = std::max_element(share.begin(), share.end(), [](const auto& a, const auto& b) {
                               return a.second < b.second;
                             })->first;
  const std::string survivor =
      running.begin()->first == victim ? std::next(running.begin())->first : running.begin()->first;
  std::vector<std::string> taken_over;
  for (const auto& [robot, owner] : owners) {
    if (owner == victim) taken_over.push_back(robot);
  }
  ASSERT_FALSE(taken_over.empty());
  std::map<std::string, std::string> now_owners;
  for (const std::string& robot : robots) now_owners[robot] = survivor;
  const Clock::time_point stopped = Clock::now();
  ASSERT_TRUE(running[victim]->stop(5s));
  expect_taken_over_within_2s(poses, taken_over, now_owners, stopped, "stopped");
  running[victim]->signal(SIGCONT);
  EXPECT_TRUE(eventually([&] { return served_as_assigned(poses, owners); }, 30s)) << running[victim]->log();
  expect_no_double_serving(poses, stopped);

  // Then it is killed: no goodbye, only its lapsed liveliness tells.
  const Clock::time_point killed = Clock::now();
  running[victim]->signal(SIGKILL);
  running[victim]->wait(10s);
  running.erase(victim);
  expect_taken_over_within_2s(poses, taken_over, now_owners, killed);
  ASSERT_TRUE(eventually([&] { return shards.live().size() == 1; }, 10s));

  // A new shard takes its share; the survivor hands those robots over without a restart.
  const std::string shard_c = start_shard_with_a_share(shards, shard_process("shard-c"), running, robots);
  ASSERT_FALSE(shard_c.empty());
  ASSERT_EQ(shards.live().size(), 2u);
  owners = expected_owners(shards.live(), robots);
  EXPECT_TRUE(eventually([&] { return served_as_assigned(poses, owners); }, 30s)) << running[survivor]->log();
  share.clear();
  for (const auto& [robot, owner] : owners) ++share[owner];
  std::printf("after a shard joined: the survivor serves %d, the new shard %d of %zu robots\n",
              share[survivor], static_cast<int>(robots.size()) - share[survivor], robots.size());

  // The fleet view names, for every robot, the shard serving it (its participant name ends with
  // the process id) and its status.
  const auto [code, fleet] = run_command(command("monitor", {"--fleet", "--duration-s", "3"}), 30s);
  EXPECT_EQ(code, 0) << fleet;
  const std::string table = fleet.substr(std::min(fleet.size(), fleet.rfind("fleet: ")));
  EXPECT_NE(table.find("fleet: 4 robot(s): 4 ok; 0 stale; served by: "), std::string::npos) << fleet;
  for (const auto& [robot, owner] : owners) {
    const std::size_t row = table.find("  " + robot + " ");
    ASSERT_NE(row, std::string::npos) << robot << " not in the fleet view:\n" << fleet;
    const std::string line = table.substr(row, table.find('\n', row) - row);
    EXPECT_NE(line.find(" ok "), std::string::npos) << line;
    EXPECT_NE(line.find(".shard."), std::string::npos) << line;
    EXPECT_EQ(line.substr(line.rfind('.') + 1), std::to_string(running[owner]->pid())) << line;
  }

  // Handed over or taken over, never served by two shards beyond a handover's delivery.
  expect_no_double_serving(poses, killed);
  for (auto& [id, shard] : running) stop_cleanly(*shard, "shard");
  stop_cleanly(decoder, "decoder");
  for (auto& gateway : gateways) stop_cleanly(*gateway, "gateway");
}

// Bad announcements on localizer_shard are refused and counted by reason, and move no robot: a
// shard id that is not its writer's, names longer than any real one, an estimator changed.
TEST_F(Shards, BadAnnouncementsAreRefusedAndCounted) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess shard(command("localizer", {"--shard"}), path("shard.log"));
  char host[256] = {};
  ASSERT_EQ(::gethostname(host, sizeof host - 1), 0);
  const std::string name = kRangeEkfLocalizer + ".shard." + host + "." + std::to_string(shard.pid());
  auto says = [&](auto pred) { return wait_for_diagnostics(diagnostics, name, pred); };
  const auto live = says(
      [](const msg::Diagnostics& d) { return d.message().find("1 live shard(s)") != std::string::npos; });
  ASSERT_NE(live.message().find("1 live shard(s)"), std::string::npos) << shard.log();

  // A shard's writer holds one instance, its own: a writer for the forged id, another for the rest.
  dds::Participant bus(dds_, "beaconloc.test.forger");
  dds::Writer forger = bus.writer<msg::LocalizerShardPubSubType>(dds::kLocalizerShardTopic);
  dds::Writer writer = bus.writer<msg::LocalizerShardPubSubType>(dds::kLocalizerShardTopic);
  ASSERT_TRUE(dds::wait_for_matched_readers({forger, writer}, scaled(10s)));
  const std::string own_id = dds::writer_id(writer->get_instance_handle());
  // One at a time, each seen counted before the next: the writer keeps the newest.
  auto write_until = [&](const dds::Writer& w, msg::LocalizerShard m, auto seen) {
    EXPECT_TRUE(w->write(&m));
    return says(seen);
  };
  msg::LocalizerShard m;
  m.participant("forger");
  m.estimator("range_ekf");
  m.shard(own_id);  // the other writer's id
  write_until(forger, m, [](const msg::Diagnostics& d) {
    return rejected_count(d, "localizer_shard.id_not_its_writer") > 0;
  });
  m.shard(own_id);
  m.estimator(std::string(300, 'x'));
  write_until(writer, m, [](const msg::Diagnostics& d) {
    return rejected_count(d, "localizer_shard.text_too_long") > 0;
  });
  m.estimator("duhl");  // another estimator's shard: no peer, accepted
  write_until(writer, m, [](const msg::Diagnostics& d) {
    return d.message().find("1 shard(s) of other estimators") != std::string::npos;
  });
  m.estimator("range_ekf");  // and now, the same writer, this one's: refused
  const msg::Diagnostics d = write_until(writer, m, [](const msg::Diagnostics& r) {
    return rejected_count(r, "localizer_shard.estimator_changed") > 0;
  });
  EXPECT_EQ(rejected_count(d, "localizer_shard.id_not_its_writer"), 1u) << d.message();
  EXPECT_EQ(rejected_count(d, "localizer_shard.text_too_long"), 1u) << d.message();
  EXPECT_EQ(rejected_count(d, "localizer_shard.estimator_changed"), 1u) << d.message();
  EXPECT_NE(d.message().find("1 live shard(s) of range_ekf"), std::string::npos) << d.message();
  EXPECT_NE(d.message().find("1 shard(s) of other estimators"), std::string::npos) << d.message();
  stop_cleanly(shard, "shard");
}

}  // namespace
}  // namespace beaconloc::testing
