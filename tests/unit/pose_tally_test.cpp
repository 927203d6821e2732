// Which writers serve a robot, from the poses alone (the monitor): two writers whose poses
// alternate serve it at once (a conflict); a writer replaced by another (a localizer restarted, a
// shard's robot taken over or handed to a new shard) is none.
#include "pose_tally.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

namespace beaconloc {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

RecordedPose pose(StampNs stamp_ns, Clock::time_point received, const std::string& writer) {
  RecordedPose p;
  p.row.robot_id = "r";
  p.row.estimator = "range_ekf";
  p.row.estimate.stamp_ns = stamp_ns;
  p.row.estimate.status = PoseStatus::kOk;
  p.received = received;
  p.writer = writer;
  return p;
}

TEST(PoseTally, AWriterTakingOverFromAnotherIsNoConflict) {
  PoseTally tally;
  const Clock::time_point t0{};
  for (int i = 0; i < 10; ++i) tally.add(pose(i * 10'000'000, t0 + i * 10ms, "a"));
  // "a" killed; "b" serves the robot 0.8 s later, "a" never again.
  for (int i = 0; i < 10; ++i) tally.add(pose(900'000'000 + i * 10'000'000, t0 + 900ms + i * 10ms, "b"));
  const RobotPoses& r = tally.robots().at("r");
  EXPECT_FALSE(r.had_conflict);
  EXPECT_EQ(r.newest->writer, "b");
  ASSERT_EQ(r.current_writers(t0 + 1000ms).size(), 1u);
  EXPECT_EQ(r.poses, 20u);
}

TEST(PoseTally, TwoWritersWhosePosesAlternateAreAConflictWhileTheyDo) {
  PoseTally tally;
  const Clock::time_point t0{};
  for (int i = 0; i < 10; ++i) {
    tally.add(pose(i * 10'000'000, t0 + i * 10ms, "a"));
    tally.add(pose(i * 10'000'000, t0 + i * 10ms + 1ms, "b"));
  }
  const RobotPoses& r = tally.robots().at("r");
  EXPECT_TRUE(r.had_conflict);
  EXPECT_EQ(r.current_writers(t0 + 100ms).size(), 2u);
  // "a" stopped: a second later only "b" serves it, the conflict stays in the record.
  for (int i = 10; i < 130; ++i) tally.add(pose(i * 10'000'000, t0 + i * 10ms, "b"));
  EXPECT_EQ(r.current_writers(t0 + 1300ms).size(), 1u);
  EXPECT_TRUE(r.had_conflict);
}

TEST(PoseTally, AWriterBackAfterItsSuccessorWithinTheWindowIsAConflict) {
  PoseTally tally;
  const Clock::time_point t0{};
  tally.add(pose(0, t0, "a"));
  tally.add(pose(10'000'000, t0 + 10ms, "b"));
  EXPECT_FALSE(tally.robots().at("r").had_conflict);
  tally.add(pose(20'000'000, t0 + 20ms, "a"));  // "a" still serves it
  EXPECT_TRUE(tally.robots().at("r").had_conflict);
}

}  // namespace
}  // namespace beaconloc
