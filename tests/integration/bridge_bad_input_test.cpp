// The bridge is an output path to ROS 2: a pose, a range or a beacon map with a non-finite
// number, from a faulty participant on the bus, never reaches a ROS 2 topic; each is counted by
// reason in the bridge's Diagnostics, and the good samples around them go through (issue 23).
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

#include "beaconloc/dds/convert.hpp"
#include "diagnostics_recorder.hpp"
#include "participants_test.hpp"
#include "process.hpp"
#include "ros2_types.hpp"
#include "sim/scenario.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class BridgeBadInput : public ParticipantsTest {};

TEST_F(BridgeBadInput, NonFiniteSamplesNeverReachRos2) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess bridge(command("bridge"), path("bridge.log"));
  dds::DdsOptions options = dds_;
  options.extra_qos_files = {std::string(BEACONLOC_SOURCE_DIR) + "/tests/integration/rviz2_readers.xml"};
  dds::Participant bus(options, "test.faulty_localizer");
  auto pose_writer = bus.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic);
  auto range_writer = bus.writer<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic);
  auto map_writer = bus.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic);
  std::mutex mutex;
  std::vector<geometry_msgs::msg::PoseWithCovarianceStamped> poses;
  std::vector<sensor_msgs::msg::Range> ranges;
  std::size_t marker_arrays = 0;
  auto pose_reader = bus.subscribe<geometry_msgs::msg::PoseWithCovarianceStampedPubSubType>(
      {"rt/beacon_pose", "", "rviz2.reader"}, [&](const auto& m) {
        std::lock_guard<std::mutex> lock(mutex);
        poses.push_back(m);
      });
  auto range_reader = bus.subscribe<sensor_msgs::msg::RangePubSubType>(
      {"rt/beacon_ranges", "", "rviz2.reader"}, [&](const auto& m) {
        std::lock_guard<std::mutex> lock(mutex);
        ranges.push_back(m);
      });
  auto markers_reader = bus.subscribe<visualization_msgs::msg::MarkerArrayPubSubType>(
      {"rt/beacons", "", "rviz2.reader"}, [&](const auto&) {
        std::lock_guard<std::mutex> lock(mutex);
        ++marker_arrays;
      });
  ASSERT_TRUE(dds::wait_for_matched_readers({pose_writer, range_writer, map_writer}, scaled(10s)))
      << bridge.log();
  // And the bridge's ROS 2 writers matched to this test's readers. The readers' own matched
  // status is not enough: a reader can match a writer before that writer has matched it, and
  // what the bridge writes to the volatile pose and range topics before then never reaches the
  // reader. So a good pose and a good range (stamp 0 s, range 1 m: both told apart from the
  // samples below) go out until one of each has come through the bridge.
  auto pose = [&](StampNs stamp_ns, double x, double var_x) {
    PoseEstimate e;
    e.stamp_ns = stamp_ns;
    e.pose_map_base = {x, 1.0, 0.2};
    e.covariance = 1e-4 * Cov3::Identity();
    e.covariance(0, 0) = var_x;
    e.status = PoseStatus::kOk;
    return dds::to_msg("robot1", e, "range_ekf", {});
  };
  auto range = [&](double range_m) {
    msg::BeaconRange m;
    m.robot_id("robot1");
    m.stamp_ns(kNsPerSecond);
    m.beacon_id(1);
    m.receiver_id(0);
    m.range_m(range_m);
    m.variance_m2(1e-4);
    m.association(msg::RANGE_ASSOCIATION_BY_ID);
    return m;
  };
  auto warmed_up = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return !poses.empty() && !ranges.empty();
  };
  ASSERT_TRUE(eventually(
      [&] {
        if (warmed_up()) return true;
        auto probe_pose = pose(0, 1.0, 1e-4);
        auto probe_range = range(1.0);
        pose_writer->write(&probe_pose);
        range_writer->write(&probe_range);
        std::this_thread::sleep_for(100ms);
        return warmed_up();
      },
      scaled(10s)))
      << bridge.log();
  // The probes are not part of what is counted below.
  auto is_probe_pose = [](const geometry_msgs::msg::PoseWithCovarianceStamped& p) {
    return p.header().stamp().sec() == 0;
  };
  auto is_probe_range = [](const sensor_msgs::msg::Range& r) { return r.range() == 1.0f; };
  const double nan = std::numeric_limits<double>::quiet_NaN();

  // Poses: good, NaN x, infinite covariance, good.
  for (auto m : {pose(kNsPerSecond, 1.0, 1e-4), pose(2 * kNsPerSecond, nan, 1e-4),
                 pose(3 * kNsPerSecond, 1.5, std::numeric_limits<double>::infinity()),
                 pose(4 * kNsPerSecond, 2.0, 1e-4)}) {
    pose_writer->write(&m);
  }
  // Ranges: good, NaN, good.
  for (auto m : {range(2.0), range(nan), range(2.5)}) range_writer->write(&m);
  // A beacon map with a NaN: no markers; then a good one: markers.
  msg::BeaconMap map = dds::to_msg(BeaconMap(sim::default_scenario().beacons), "map");
  msg::BeaconMap bad_map = map;
  bad_map.beacons()[0].x_m(nan);
  map_writer->write(&bad_map);
  // The topic keeps only the newest map: the good one goes once the bad one was refused.
  const auto refused = wait_for_diagnostics(
      diagnostics, "beaconloc.bridge.robot1",
      [](const msg::Diagnostics& d) { return rejected_count(d, "beacon_map.non_finite_position") > 0; });
  EXPECT_EQ(rejected_count(refused, "beacon_map.non_finite_position"), 1u) << refused.message();
  map_writer->write(&map);

  // Everything is through once the last sample of each kind is: the bridge handles a topic's
  // samples in order and writes what it passes on in that order, so a bad sample that got through
  // would have arrived before the good one written after it (the map: before the good map's
  // markers, as the bad map was refused before the good one was written).
  ASSERT_TRUE(eventually(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        const bool last_pose = std::any_of(poses.begin(), poses.end(),
                                           [](const auto& p) { return p.header().stamp().sec() == 4; });
        const bool last_range =
            std::any_of(ranges.begin(), ranges.end(), [](const auto& r) { return r.range() == 2.5f; });
        return last_pose && last_range && marker_arrays >= 1;
      },
      scaled(10s)))
      << [&] {
           // Which kind did not arrive (a range or pose the bridge read later than its 600 ms
           // lifespan is dropped by DDS, uncounted), and what the bridge counted.
           std::lock_guard<std::mutex> lock(mutex);
           std::string seen = "poses at s:";
           for (const auto& p : poses) seen += " " + std::to_string(p.header().stamp().sec());
           seen += "; ranges:";
           for (const auto& r : ranges) seen += " " + std::to_string(r.range());
           seen += "; marker arrays: " + std::to_string(marker_arrays) + "\n";
           return seen + bridge.log();
         }();
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_EQ(std::count_if(poses.begin(), poses.end(), [&](const auto& p) { return !is_probe_pose(p); }), 2);
    for (const auto& p : poses) {
      EXPECT_TRUE(std::isfinite(p.pose().pose().position().x()));
      for (double c : p.pose().covariance()) EXPECT_TRUE(std::isfinite(c));
    }
    EXPECT_EQ(std::count_if(ranges.begin(), ranges.end(), [&](const auto& r) { return !is_probe_range(r); }), 2);
    for (const auto& r : ranges) EXPECT_TRUE(std::isfinite(r.range()));
    EXPECT_EQ(marker_arrays, 1u);
  }
  // A report that has counted every refusal: a report taken before the bad pose or the bad range
  // was counted would show fewer.
  const auto latest =
      wait_for_diagnostics(diagnostics, "beaconloc.bridge.robot1", [](const msg::Diagnostics& d) {
        return rejected_count(d, "pose.unusable") >= 2 && rejected_count(d, "range.unusable") >= 1 &&
               rejected_count(d, "beacon_map.non_finite_position") >= 1;
      });
  EXPECT_EQ(rejected_count(latest, "pose.unusable"), 2u);
  EXPECT_EQ(rejected_count(latest, "range.unusable"), 1u);
  EXPECT_EQ(rejected_count(latest, "beacon_map.non_finite_position"), 1u);
  stop_cleanly(bridge, "bridge");
}

}  // namespace
}  // namespace beaconloc::testing
