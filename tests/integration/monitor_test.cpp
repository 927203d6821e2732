// `beaconloc monitor` and the liveness of participants, with the participants as processes on
// loopback: a participant that stops or is killed shows as gone or silent, never ok; the monitor
// keeps O(robots) of the pose stream unless it scores or writes, writes every pose when asked
// to, and prints or writes no non-finite number. A test kills a process: the
// UDP-only loopback profile (a killed process cannot remove shared-memory segments).
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <functional>
#include <limits>
#include <regex>
#include <sstream>
#include <thread>

#include "beaconloc/dds/convert.hpp"
#include "diagnostics_recorder.hpp"
#include "participants_test.hpp"
#include "pose_recorder.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

// Polls until done() holds; false on timeout (scaled()).
bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + scaled(timeout);
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(50ms);
  }
  return true;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

bool has_line_starting(const std::string& text, const std::string& prefix) {
  for (const auto& line : lines_of(text)) {
    if (line.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

// The last line of the text that starts with the prefix ("" when none).
std::string last_line_starting(const std::string& text, const std::string& prefix) {
  std::string found;
  for (const auto& line : lines_of(text)) {
    if (line.rfind(prefix, 0) == 0) found = line;
  }
  return found;
}

// "nan", "inf", "-nan", "infinity" as a word of their own: a number printf made of a non-finite value.
bool has_non_finite_number(const std::string& text) {
  static const std::regex number(R"((^|[^a-z])-?(nan|inf|infinity)([^a-z]|$))", std::regex::icase);
  return std::regex_search(text, number);
}

class Monitor : public ParticipantsTest {
 protected:
  Monitor() : ParticipantsTest("beaconloc.loopback_udp") {}

  bool wait_for_line(const ChildProcess& p, const std::string& prefix, std::chrono::milliseconds timeout) {
    return wait_until([&] { return has_line_starting(p.log(), prefix); }, timeout);
  }

  static msg::PoseEstimate pose(const std::string& robot, StampNs stamp_ns, double x_m) {
    PoseEstimate e;
    e.stamp_ns = stamp_ns;
    e.pose_map_base = Pose2(x_m, 1.0, 0.1);
    e.covariance = Cov3::Identity() * 0.01;
    e.status = PoseStatus::kOk;
    return dds::to_msg(robot, e, "test_estimator", {});
  }
  // Writes every pose and waits for each batch to be acknowledged: the writer keeps 10 per
  // robot, and a reliable keep-last writer overwrites what no reader has acknowledged yet.
  static void write_acknowledged(eprosima::fastdds::dds::DataWriter* writer,
                                 std::vector<msg::PoseEstimate> poses) {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      ASSERT_TRUE(writer->write(&poses[i]));
      if (i % 8 == 7 || i + 1 == poses.size()) {
        ASSERT_EQ(writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(10, 0)),
                  ReturnCode_t::RETCODE_OK);
      }
    }
  }
};

// Item 2 of issue 23: the monitor kept the last Diagnostics of a dead participant and showed it
// ok. A gateway killed with SIGKILL shows silent after three periods, then gone once DDS's lease
// (10 s) expires: its instance turns NOT_ALIVE_NO_WRITERS. A decoder stopped with SIGTERM shows
// gone (stopped) at once: it disposed its instance. Neither is ever shown ok again, nor in the
// table at the end; and the monitor says it heard no pose at all.
TEST_F(Monitor, AParticipantThatStopsOrIsKilledShowsGoneOrSilentNeverOk) {
  ChildProcess monitor(command("monitor"), path("monitor.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  ChildProcess gateway(command("gateway", {"--robot", "g1"}), path("gateway.log"));
  ASSERT_TRUE(wait_for_line(monitor, "beaconloc.gateway.g1: ok", 20s)) << monitor.log();
  ASSERT_TRUE(wait_for_line(monitor, "beaconloc.decoder: ", 20s)) << monitor.log();

  gateway.signal(SIGKILL);
  ASSERT_TRUE(gateway.wait(5s));
  const auto killed = std::chrono::steady_clock::now();
  ASSERT_TRUE(wait_for_line(monitor, "beaconloc.gateway.g1: silent ", 10s)) << monitor.log();
  const double silent_after_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  ASSERT_TRUE(wait_for_line(monitor, "beaconloc.gateway.g1: gone (no live writer)", 30s)) << monitor.log();
  const double gone_after_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();

  ASSERT_NO_FATAL_FAILURE(stop_cleanly(decoder, "decoder"));
  ASSERT_TRUE(wait_for_line(monitor, "beaconloc.decoder: gone (stopped)", 10s)) << monitor.log();
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(monitor, "monitor"));
  std::printf("gateway killed: silent after %.1f s, gone after %.1f s\n", silent_after_s, gone_after_s);

  const std::string out = monitor.log();
  // Once gone, never shown ok again (the final table included).
  for (const char* name : {"beaconloc.gateway.g1: ", "beaconloc.decoder: "}) {
    const std::string last = last_line_starting(out, name);
    EXPECT_EQ(last.rfind(std::string(name) + "gone", 0), 0u) << last;
    EXPECT_EQ(last.find(": ok"), std::string::npos) << last;
  }
  const auto after_kill = out.find("beaconloc.gateway.g1: silent ");
  EXPECT_EQ(out.find("beaconloc.gateway.g1: ok", after_kill), std::string::npos) << out;
  EXPECT_TRUE(has_line_starting(out, "monitor: no pose received (")) << out;  // each second
  EXPECT_EQ(lines_of(out).back(), "monitor: no pose received") << out;
}

// Item 12 of issue 23: the monitor kept (and copied each second) every pose. Without --truth or
// --out it keeps the newest of each robot: one stored pose per robot after 900 poses, the counts
// exact; recording every pose (scoring) keeps all of them, a correction replacing its pose. A
// non-finite pose is refused by both, and counted.
TEST_F(Monitor, TheRecorderKeepsOnePosePerRobotUnlessItRecordsEveryPose) {
  PoseRecorder newest(dds_, PoseRecorder::Keep::kNewestPerRobot);
  PoseRecorder every(dds_, PoseRecorder::Keep::kEveryPose);
  dds::Participant bus(dds_, "test.localizer");
  auto* writer = bus.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic);
  ASSERT_TRUE(wait_until(
      [&] {
        eprosima::fastdds::dds::PublicationMatchedStatus s;
        writer->get_publication_matched_status(s);
        return s.current_count == 2;
      },
      10s));
  std::vector<msg::PoseEstimate> sent;
  for (int i = 1; i <= 300; ++i) {
    for (const char* robot : {"a", "b", "c"})
      sent.push_back(pose(robot, i * 10 * kNsPerMillisecond, 0.01 * i));
  }
  sent.push_back(pose("a", 300 * 10 * kNsPerMillisecond, 42.0));  // a correction of a's last pose
  auto bad = pose("b", 301 * 10 * kNsPerMillisecond, std::numeric_limits<double>::quiet_NaN());
  sent.push_back(bad);
  bad = pose("c", 301 * 10 * kNsPerMillisecond, 1.0);
  bad.covariance()[4] = std::numeric_limits<double>::infinity();
  sent.push_back(bad);
  ASSERT_NO_FATAL_FAILURE(write_acknowledged(writer, sent));
  auto got_all = [](const PoseRecorder& r) {
    const auto robots = r.robots();
    return r.count() == 900 && robots.size() == 3 && robots.at("c").non_finite == 1;
  };
  ASSERT_TRUE(wait_until([&] { return got_all(newest) && got_all(every); }, 10s));

  EXPECT_EQ(newest.count(), 900u);
  EXPECT_EQ(newest.stored(), 3u);  // O(robots)
  EXPECT_EQ(every.stored(), 900u);
  const auto robots = newest.robots();
  EXPECT_EQ(robots.at("a").poses, 300u);
  EXPECT_EQ(robots.at("b").non_finite, 1u);
  EXPECT_EQ(robots.at("c").non_finite, 1u);
  ASSERT_TRUE(robots.at("a").newest);
  EXPECT_EQ(robots.at("a").newest->row.estimate.pose_map_base.x(), 42.0);  // the correction
  ASSERT_TRUE(robots.at("b").newest);
  EXPECT_EQ(robots.at("b").newest->row.estimate.stamp_ns, 300 * 10 * kNsPerMillisecond);  // not the NaN one
  for (const auto& p : newest.poses()) EXPECT_TRUE(is_finite(p.row.estimate));
  std::size_t corrected = 0;
  for (const auto& p : every.poses()) {
    EXPECT_TRUE(is_finite(p.row.estimate));
    corrected += p.row.estimate.pose_map_base.x() == 42.0;
  }
  EXPECT_EQ(corrected, 1u);
  bus.close();
}

// The monitor with --out writes every pose it got, and neither its lines nor the file carry a
// non-finite number: a pose with one is refused and counted (even as the newest of its robot).
TEST_F(Monitor, WithOutTheMonitorWritesEveryPoseAndNoNonFiniteNumber) {
  ChildProcess monitor(command("monitor", {"--out", path("poses.csv")}), path("monitor.log"));
  dds::Participant bus(dds_, "test.localizer");
  auto* writer = bus.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic);
  ASSERT_TRUE(dds::wait_for_matched_readers({writer}, scaled(15s))) << monitor.log();
  std::vector<msg::PoseEstimate> sent;
  for (int i = 1; i <= 250; ++i) {
    for (const char* robot : {"ra", "rb"}) sent.push_back(pose(robot, i * 10 * kNsPerMillisecond, 0.01 * i));
  }
  sent.push_back(pose("ra", 251 * 10 * kNsPerMillisecond, std::numeric_limits<double>::infinity()));
  auto bad = pose("rb", 251 * 10 * kNsPerMillisecond, 1.0);
  bad.covariance()[0] = std::numeric_limits<double>::quiet_NaN();
  sent.push_back(bad);
  ASSERT_NO_FATAL_FAILURE(write_acknowledged(writer, sent));
  ASSERT_TRUE(wait_until(
      [&] {
        const std::string out = monitor.log();
        return out.find("ra test_estimator: 250 poses") != std::string::npos &&
               out.find("rb test_estimator: 250 poses") != std::string::npos;
      },
      15s))
      << monitor.log();
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(monitor, "monitor"));

  const std::string out = monitor.log();
  EXPECT_FALSE(has_non_finite_number(out)) << out;
  EXPECT_NE(out.find("1 non-finite refused"), std::string::npos) << out;
  EXPECT_EQ(lines_of(out).back(), "monitor: 500 poses of 2 robot(s), 2 non-finite poses refused") << out;
  const auto rows = load_estimates_csv(path("poses.csv"));
  EXPECT_EQ(rows.size(), 500u);
  for (const auto& r : rows) EXPECT_TRUE(is_finite(r.estimate)) << r.robot_id << ' ' << r.estimate.stamp_ns;
}

}  // namespace
}  // namespace beaconloc::testing
