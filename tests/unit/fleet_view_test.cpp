// `beaconloc monitor --fleet` without DDS: a row per robot with its pose status, its pose rate
// between two views, its age, its gateway's rejections and the participant serving it; stale
// robots and the share of each localizer in the summary.
#include "fleet_view.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <string>

namespace beaconloc::cli {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const std::string kShardA = "0102030405060708090a0b0c";  // participant ids: 24 hex digits
const std::string kShardB = "0102030405060708090a0bff";

void add_poses(PoseTally& tally, const std::string& robot, const std::string& participant, int n,
               Clock::time_point from, PoseStatus status) {
  for (int i = 0; i < n; ++i) {
    RecordedPose p;
    p.row.robot_id = robot;
    p.row.estimator = "range_ekf";
    p.row.estimate.stamp_ns = (from.time_since_epoch().count() / 1'000'000) * 1'000'000 + i * 10'000'000;
    p.row.estimate.status = status;
    p.received = from + i * 10ms;
    p.writer = participant + "00000102";
    tally.add(p);
  }
}

TEST(FleetView, ARowPerRobotWithItsRateAgeRejectionsAndServingShard) {
  const std::map<std::string, FleetParticipant> participants{
      {kShardA, {"beaconloc.localizer.range_ekf.shard.a", 3}},
      {kShardB, {"beaconloc.localizer.range_ekf.shard.b", 0}},
      {"aaaaaaaaaaaaaaaaaaaaaaaa", {"beaconloc.gateway.r1", 7}},
  };
  PoseTally tally;
  const Clock::time_point t0{};
  add_poses(tally, "r1", kShardA, 100, t0, PoseStatus::kOk);
  add_poses(tally, "r2", kShardB, 100, t0, PoseStatus::kInitializing);
  FleetView view;
  auto rows = view.update(tally.robots(), participants, t0 + 1s);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].pose_rate_hz, 0.0);  // no earlier view
  // One more second: r1 50 poses, r2 none (its shard stopped).
  add_poses(tally, "r1", kShardA, 50, t0 + 1s, PoseStatus::kOk);
  rows = view.update(tally.robots(), participants, t0 + 3s);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].robot, "r1");
  EXPECT_DOUBLE_EQ(rows[0].pose_rate_hz, 25.0);  // 50 poses over 2 s
  EXPECT_EQ(rows[0].status, PoseStatus::kOk);
  EXPECT_NEAR(rows[0].age_s, 3.0 - 1.49, 1e-9);
  EXPECT_EQ(rows[0].gateway_rejected, 7u);
  EXPECT_EQ(rows[0].served_by, "beaconloc.localizer.range_ekf.shard.a");
  EXPECT_FALSE(rows[0].stale);
  EXPECT_EQ(rows[1].robot, "r2");
  EXPECT_EQ(rows[1].pose_rate_hz, 0.0);
  EXPECT_TRUE(rows[1].stale);                          // 2.01 s without a pose
  EXPECT_FALSE(rows[1].gateway_rejected.has_value());  // no gateway of that name reports
  const std::string text = format_fleet(rows);
  EXPECT_NE(text.find("fleet: 2 robot(s): 1 initializing, 1 ok; 1 stale; served by: "
                      "beaconloc.localizer.range_ekf.shard.a 1\n"),
            std::string::npos)
      << text;
}

TEST(FleetView, AWriterWhoseParticipantNeverReportedIsShownByItsId) {
  PoseTally tally;
  add_poses(tally, "r1", kShardA, 2, Clock::time_point{}, PoseStatus::kOk);
  FleetView view;
  const auto rows = view.update(tally.robots(), {}, Clock::time_point{} + 100ms);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].served_by, kShardA);
  const std::string empty = format_fleet({});
  EXPECT_EQ(empty.substr(0, empty.find('\n')), "fleet: 0 robot(s); 0 stale; served by: none");
}

}  // namespace
}  // namespace beaconloc::cli
