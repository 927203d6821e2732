#pragma once
// What the shard tests check (integration.Shards, multihost.*): which shard the assignment gives
// each robot, which one its poses come from, and how soon a dead shard's robots are served again.
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "beaconloc/core/shard_assignment.hpp"
#include "beaconloc/dds/participant.hpp"
#include "pose_recorder.hpp"
#include "process.hpp"
#include "shard_watcher.hpp"

namespace beaconloc::testing {

using Clock = std::chrono::steady_clock;

// robot -> the participant (dds::participant_of_writer) that should serve it among `shards`.
inline std::map<std::string, std::string> expected_owners(const std::set<std::string>& shards,
                                                          const std::vector<std::string>& robots) {
  ShardAssignment assignment(*shards.begin());
  assignment.set_live({shards.begin(), shards.end()});
  std::map<std::string, std::string> out;
  for (const std::string& robot : robots) out[robot] = dds::participant_of_writer(assignment.owner(robot));
  return out;
}

// Whether every robot's newest pose came from the participant the assignment gives it, ok.
inline bool served_as_assigned(const PoseRecorder& poses, const std::map<std::string, std::string>& owners) {
  const auto robots = poses.robots();
  return std::all_of(owners.begin(), owners.end(), [&](const auto& robot_owner) {
    const auto it = robots.find(robot_owner.first);
    return it != robots.end() && it->second.newest &&
           it->second.newest->row.estimate.status == PoseStatus::kOk &&
           dds::participant_of_writer(it->second.newest->writer) == robot_owner.second;
  });
}

// The writers of a robot's poses in turn: "participant from +t s" (since `since`), for a failure.
inline std::string writer_turns(const PoseRecorder& poses, const std::string& robot,
                                Clock::time_point since) {
  std::string out, writer;
  for (const RecordedPose& p : poses.poses()) {
    if (p.row.robot_id != robot || p.writer == writer) continue;
    writer = p.writer;
    out += "\n  " + dds::participant_of_writer(writer) + " from " +
           std::to_string(std::chrono::duration<double>(p.received - since).count()) + " s";
  }
  return out;
}

// The first pose of robot, received at or after `since`, from `participant`'s writer (ok ones alone
// with ok_only): seconds after `since`.
inline std::optional<double> first_pose_from(const PoseRecorder& poses, const std::string& robot,
                                             const std::string& participant, Clock::time_point since,
                                             bool ok_only) {
  std::optional<double> first;
  for (const RecordedPose& p : poses.poses()) {
    if (p.row.robot_id != robot || p.received < since || dds::participant_of_writer(p.writer) != participant)
      continue;
    if (ok_only && p.row.estimate.status != PoseStatus::kOk) continue;
    const double s = std::chrono::duration<double>(p.received - since).count();
    if (!first || s < *first) first = s;
  }
  return first;
}

// Odometry stamps at which two shards published a pose of the robot: each shard publishes one
// pose per odometry stamp it serves, so these are the steps the robot was served twice. A
// handover shares a few (the old shard serves until it hears the new one); a late-delivered
// pose of the old shard, a shard taking its robots back after a stall, share none.
inline std::size_t stamps_served_twice(const PoseRecorder& poses, const std::string& robot) {
  std::map<StampNs, std::set<std::string>> writers_at;
  for (const RecordedPose& p : poses.poses()) {
    if (p.row.robot_id == robot) writers_at[p.row.estimate.stamp_ns].insert(p.writer);
  }
  return static_cast<std::size_t>(std::count_if(writers_at.begin(), writers_at.end(),
                                                [](const auto& at) { return at.second.size() > 1; }));
}

// Expects no robot served twice for more than 20 odometry steps (0.2 s; scaled() under the
// sanitizers), printing the most; `since` dates the writer turns printed on failure.
inline void expect_no_double_serving(const PoseRecorder& poses, Clock::time_point since) {
  std::size_t most = 0;
  for (const auto& [robot, r] : poses.robots()) {
    const std::size_t twice = stamps_served_twice(poses, robot);
    most = std::max(most, twice);
    EXPECT_LE(twice, static_cast<std::size_t>(20 * kTimeScale))
        << robot << ": " << twice
        << " odometry steps served by two shards; writers in turn:" << writer_turns(poses, robot, since);
  }
  std::printf("most odometry steps of one robot served by two shards: %zu\n", most);
}

// Starts a shard (start) and waits for its announcement; `running` keeps it by its participant id,
// which is returned ("" with a test failure when it never announces itself).
inline std::string start_shard(const ShardWatcher& shards,
                               const std::function<std::unique_ptr<ChildProcess>()>& start,
                               std::map<std::string, std::unique_ptr<ChildProcess>>& running) {
  using namespace std::chrono_literals;
  const std::set<std::string> before = shards.live();
  std::unique_ptr<ChildProcess> shard = start();
  std::string id;
  EXPECT_TRUE(eventually(
      [&] {
        for (const std::string& s : shards.live()) {
          if (!before.count(s)) id = dds::participant_of_writer(s);
        }
        return !id.empty();
      },
      20s))
      << "a shard never announced itself:\n"
      << shard->log();
  if (!id.empty()) running[id] = std::move(shard);
  return id;
}

// Starts a shard that the assignment gives at least one of `robots` (a shard's id is random:
// with few robots, one may fall to none), stopping and starting again up to five times; returns
// its participant id ("" with a test failure when none got a robot).
inline std::string start_shard_with_a_share(const ShardWatcher& shards,
                                            const std::function<std::unique_ptr<ChildProcess>()>& start,
                                            std::map<std::string, std::unique_ptr<ChildProcess>>& running,
                                            const std::vector<std::string>& robots) {
  using namespace std::chrono_literals;
  for (int attempt = 0; attempt < 5; ++attempt) {
    const std::string id = start_shard(shards, start, running);
    if (id.empty()) return id;
    for (const auto& [robot, owner] : expected_owners(shards.live(), robots)) {
      if (owner == id) return id;
    }
    running[id]->signal(SIGTERM);
    EXPECT_TRUE(running[id]->wait(15s));
    running.erase(id);
    EXPECT_TRUE(eventually(
        [&] {
          const auto live = shards.live();
          return std::none_of(live.begin(), live.end(),
                              [&](const std::string& s) { return dds::participant_of_writer(s) == id; });
        },
        10s));
  }
  ADD_FAILURE() << "five shards in turn, none given a robot";
  return "";
}

// The robots of a shard killed (or stopped: `what`) at `killed`, each served again by the shard
// `owners` now gives it: prints how long after its first pose and its first ok pose came, and
// expects the first within issue 19's 2 s (scaled() under the sanitizers).
inline void expect_taken_over_within_2s(const PoseRecorder& poses, const std::vector<std::string>& robots,
                                        const std::map<std::string, std::string>& owners,
                                        Clock::time_point killed, const char* what = "killed") {
  using namespace std::chrono_literals;
  for (const std::string& robot : robots) {
    const std::string& owner = owners.at(robot);
    EXPECT_TRUE(
        eventually([&] { return first_pose_from(poses, robot, owner, killed, true).has_value(); }, 10s))
        << robot << " not served again after its shard was killed";
    const auto first = first_pose_from(poses, robot, owner, killed, false);
    const auto first_ok = first_pose_from(poses, robot, owner, killed, true);
    if (!first || !first_ok) continue;
    std::printf("takeover: %s served again %.2f s after its shard was %s, ok %.2f s after\n", robot.c_str(),
                *first, what, *first_ok);
    EXPECT_LE(*first, std::chrono::duration<double>(scaled(2000ms)).count()) << robot;
  }
}

}  // namespace beaconloc::testing
