// Localizer shards (issue 19): `beaconloc localizer --shard` processes share the robots among the
// live ones with no coordinator (rendezvous hashing on their announcement writers' ids); a shard
// killed has its robots served again by the others within 2 s, re-localized from the beacons; a
// shard started later takes its share without a restart of the others. Never two shards'
// poses of one robot at once.
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "beaconloc/core/shard_assignment.hpp"
#include "participants_test.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// The live shards, as their announcements (LocalizerShard) and its liveliness tell.
class ShardWatcher {
 public:
  explicit ShardWatcher(const dds::DdsOptions& dds) : participant_(dds, "beaconloc.test.shards") {
    dds::ReaderEvents<msg::LocalizerShard> events;
    events.on_writer_gone = [this](const std::string& writer) {
      std::lock_guard<std::mutex> lock(mutex_);
      live_.erase(writer);
    };
    reader_ = participant_.subscribe_with_info<msg::LocalizerShardPubSubType>(
        dds::kLocalizerShardTopic,
        [this](const msg::LocalizerShard&, const eprosima::fastdds::dds::SampleInfo& info) {
          std::lock_guard<std::mutex> lock(mutex_);
          live_.insert(dds::writer_id(info.publication_handle));
        },
        events);
  }
  std::set<std::string> live() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return live_;
  }

 private:
  mutable std::mutex mutex_;
  std::set<std::string> live_;  // announcement writer ids
  dds::Participant participant_;
  dds::Reader reader_;
};

// robot -> the participant (dds::participant_of_writer) that should serve it among `shards`.
std::map<std::string, std::string> expected_owners(const std::set<std::string>& shards,
                                                   const std::vector<std::string>& robots) {
  ShardAssignment assignment(*shards.begin());
  assignment.set_live({shards.begin(), shards.end()});
  std::map<std::string, std::string> out;
  for (const std::string& robot : robots) out[robot] = dds::participant_of_writer(assignment.owner(robot));
  return out;
}

// Whether every robot's newest pose came from the participant the assignment gives it.
bool served_as_assigned(const PoseRecorder& poses, const std::map<std::string, std::string>& owners) {
  const auto robots = poses.robots();
  return std::all_of(owners.begin(), owners.end(), [&](const auto& robot_owner) {
    const auto it = robots.find(robot_owner.first);
    return it != robots.end() && it->second.newest &&
           dds::participant_of_writer(it->second.newest->writer) == robot_owner.second;
  });
}

// The writers of a robot's poses in turn: "participant from +t s" (since `since`), for a failure.
std::string writer_turns(const PoseRecorder& poses, const std::string& robot, Clock::time_point since) {
  std::string out, writer;
  for (const RecordedPose& p : poses.poses()) {
    if (p.row.robot_id != robot || p.writer == writer) continue;
    writer = p.writer;
    out += "\n  " + dds::participant_of_writer(writer) + " from " +
           std::to_string(std::chrono::duration<double>(p.received - since).count()) + " s";
  }
  return out;
}

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
    gateways.push_back(std::make_unique<ChildProcess>(command("gateway", {"--robot", robot, "--duration-s", "0"}),
                                                      path("gateway-" + robot + ".log")));
  }
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  // Shards by their participant id (the announcement's writer's prefix).
  std::map<std::string, std::unique_ptr<ChildProcess>> running;
  auto start_shard = [&](const std::string& name) {
    const std::set<std::string> before = shards.live();
    auto shard = std::make_unique<ChildProcess>(command("localizer", {"--shard"}), path(name + ".log"));
    std::string id;
    EXPECT_TRUE(eventually(
        [&] {
          for (const std::string& s : shards.live()) {
            if (!before.count(s)) id = dds::participant_of_writer(s);
          }
          return !id.empty();
        },
        20s))
        << name << " never announced itself:\n"
        << shard->log();
    running[id] = std::move(shard);
    return id;
  };
  start_shard("shard-a");
  start_shard("shard-b");
  ASSERT_EQ(shards.live().size(), 2u);

  // Every robot served, each by the shard the assignment gives it.
  auto owners = expected_owners(shards.live(), robots);
  ASSERT_TRUE(eventually([&] { return served_as_assigned(poses, owners); }, 30s))
      << running.begin()->second->log();
  std::map<std::string, int> share;
  for (const auto& [robot, owner] : owners) ++share[owner];
  std::printf("two shards: %d and %d of %zu robots\n", share[running.begin()->first],
              share[std::next(running.begin())->first], robots.size());

  // The shard serving the most robots is killed: no goodbye, only its lapsed liveliness tells.
  const std::string victim =
      std::max_element(share.begin(), share.end(), [](const auto& a, const auto& b) { return a.second < b.second; })
          ->first;
  const Clock::time_point killed = Clock::now();
  running[victim]->signal(SIGKILL);
  running[victim]->wait(10s);
  running.erase(victim);
  const std::string survivor = running.begin()->first;
  std::vector<std::string> taken_over;
  for (const auto& [robot, owner] : owners) {
    if (owner == victim) taken_over.push_back(robot);
  }
  ASSERT_FALSE(taken_over.empty());
  // The first pose of each of its robots from the survivor, and the first ok one.
  auto first_pose_after_kill = [&](const std::string& robot, bool ok_only) -> std::optional<double> {
    std::optional<double> first;
    for (const RecordedPose& p : poses.poses()) {
      if (p.row.robot_id != robot || p.received < killed || dds::participant_of_writer(p.writer) != survivor) continue;
      if (ok_only && p.row.estimate.status != PoseStatus::kOk) continue;
      const double s = std::chrono::duration<double>(p.received - killed).count();
      if (!first || s < *first) first = s;
    }
    return first;
  };
  for (const std::string& robot : taken_over) {
    EXPECT_TRUE(eventually([&] { return first_pose_after_kill(robot, true).has_value(); }, 10s))
        << robot << " not served again after its shard was killed:\n"
        << running[survivor]->log();
    const auto first = first_pose_after_kill(robot, false);
    const auto first_ok = first_pose_after_kill(robot, true);
    if (!first || !first_ok) continue;
    std::printf("takeover: %s served again %.2f s after its shard was killed, ok %.2f s after\n", robot.c_str(),
                *first, *first_ok);
    // Issue 19: within 2 s (the sanitizers' slower processes: scaled).
    EXPECT_LE(*first, std::chrono::duration<double>(scaled(2000ms)).count()) << robot;
  }
  ASSERT_TRUE(eventually([&] { return shards.live().size() == 1; }, 10s));

  // A new shard takes its share; the survivor hands those robots over without a restart.
  start_shard("shard-c");
  ASSERT_EQ(shards.live().size(), 2u);
  owners = expected_owners(shards.live(), robots);
  EXPECT_TRUE(eventually([&] { return served_as_assigned(poses, owners); }, 30s)) << running[survivor]->log();
  share.clear();
  for (const auto& [robot, owner] : owners) ++share[owner];
  std::printf("after a shard joined: the survivor serves %d, the new shard %d of %zu robots\n", share[survivor],
              static_cast<int>(robots.size()) - share[survivor], robots.size());

  // Handed over or taken over, never served by two shards at once (poses alternating).
  for (const auto& [robot, r] : poses.robots()) {
    EXPECT_FALSE(r.had_conflict) << robot << ": two shards at once; writers in turn:" << writer_turns(poses, robot, killed);
  }
  for (auto& [id, shard] : running) stop_cleanly(*shard, "shard");
  stop_cleanly(decoder, "decoder");
  for (auto& gateway : gateways) stop_cleanly(*gateway, "gateway");
}

}  // namespace
}  // namespace beaconloc::testing
