// `beaconloc monitor` and the liveness of participants, with the participants as processes on
// loopback: a participant that stops or is killed shows as gone or silent, never ok; two
// localizers serving one robot both report the conflict (and so does the monitor) until one
// stops; the monitor keeps O(robots) of the pose stream unless it scores or writes, writes every
// pose when asked to, and prints or writes no non-finite number. A test kills a process: the
// UDP-only loopback profile (a killed process cannot remove shared-memory segments).
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <fstream>
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
  static void write_acknowledged(const dds::Writer& writer,
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

// Item 11 of issue 23: two localizers serving one robot went unnoticed. Each lists the robots it
// serves in its Diagnostics and reads the others': both report the conflict (degraded, counted,
// naming the robot and the other localizer) and publish that robot's poses degraded while it
// lasts; the monitor sees two writers of one robot. When one stops, the other clears.
TEST_F(Monitor, TwoLocalizersServingOneRobotBothReportTheConflictUntilOneStops) {
  const std::string ekf = "beaconloc.localizer.range_ekf", duhl = "beaconloc.localizer.duhl";
  DiagnosticsRecorder diagnostics(dds_);
  PoseRecorder poses(dds_);
  ChildProcess monitor(command("monitor"), path("monitor.log"));
  ChildProcess ekf_localizer(command("localizer", {"--estimator", "range_ekf"}), path("range_ekf.log"));
  ChildProcess duhl_localizer(command("localizer", {"--estimator", "duhl"}), path("duhl.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  // Until stopped (--duration-s 0): it runs through every wait below, however long they take.
  ChildProcess gateway(command("gateway", {"--robot", "robot1", "--duration-s", "0", "--seed", "3"}),
                       path("gateway.log"));

  auto in_conflict = [](const std::map<std::string, msg::Diagnostics>& latest, const std::string& name,
                        const std::string& other) {
    if (!latest.count(name)) return false;
    const auto& d = latest.at(name);
    return d.status() == msg::PARTICIPANT_STATUS_DEGRADED && d.serving_conflicts() >= 1 &&
           d.message().find("robot robot1 also served by " + other) != std::string::npos;
  };
  std::map<std::string, msg::Diagnostics> latest;
  ASSERT_TRUE(wait_until(
      [&] {
        latest = diagnostics.latest();
        return in_conflict(latest, ekf, duhl) && in_conflict(latest, duhl, ekf);
      },
      30s))
      << ekf_localizer.log() << duhl_localizer.log();
  std::printf("%s: %s\n%s: %s\n", ekf.c_str(), latest.at(ekf).message().c_str(), duhl.c_str(),
              latest.at(duhl).message().c_str());
  // Each lists the robot it serves.
  ASSERT_EQ(latest.at(ekf).robots_localized().size(), 1u);
  EXPECT_EQ(latest.at(ekf).robots_localized()[0], "robot1");
  // A pose either writes for an odometry sample stamped after its conflicting report (the
  // gateway stamps with the wall clock) was estimated after it found the conflict: never ok.
  const std::map<std::string, StampNs> conflict_from{{"range_ekf", latest.at(ekf).stamp_ns()},
                                                     {"duhl", latest.at(duhl).stamp_ns()}};
  std::map<std::string, std::size_t> during, ok_during;
  ASSERT_TRUE(wait_until(
      [&] {
        during.clear();
        ok_during.clear();
        for (const auto& p : poses.poses()) {
          const auto from = conflict_from.find(p.row.estimator);
          if (from == conflict_from.end() || p.row.estimate.stamp_ns <= from->second) continue;
          ++during[p.row.estimator];
          if (p.row.estimate.status == PoseStatus::kOk) ++ok_during[p.row.estimator];
        }
        return during["range_ekf"] >= 100 && during["duhl"] >= 100;
      },
      30s));
  EXPECT_EQ(ok_during["range_ekf"], 0u);
  EXPECT_EQ(ok_during["duhl"], 0u);
  ASSERT_TRUE(wait_for_line(monitor, "robot1 ", 10s));
  ASSERT_TRUE(wait_until(
      [&] { return monitor.log().find("CONFLICT: poses from 2 localizers at once") != std::string::npos; },
      10s))
      << monitor.log();

  ASSERT_NO_FATAL_FAILURE(stop_cleanly(duhl_localizer, "duhl localizer"));
  ASSERT_TRUE(wait_until(
      [&] {
        latest = diagnostics.latest();
        return latest.at(ekf).message().find("serving conflict") == std::string::npos;
      },
      10s))
      << latest.at(ekf).message();
  EXPECT_GE(latest.at(ekf).serving_conflicts(), 1u);  // the count stays
  const StampNs cleared_at = latest.at(ekf).stamp_ns();
  ASSERT_TRUE(wait_until(
      [&] {
        const auto newest = poses.newest();
        return newest && newest->row.estimator == "range_ekf" && newest->row.estimate.stamp_ns > cleared_at &&
               newest->row.estimate.status == PoseStatus::kOk;
      },
      20s))
      << ekf_localizer.log();

  ASSERT_NO_FATAL_FAILURE(stop_cleanly(gateway, "gateway"));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(decoder, "decoder"));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(ekf_localizer, "range_ekf localizer"));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(monitor, "monitor"));
  const std::string conflict =
      last_line_starting(monitor.log(), "conflict: robot1 got poses from 2 localizers at once:");
  EXPECT_NE(conflict.find("range_ekf ("), std::string::npos) << monitor.log();
  EXPECT_NE(conflict.find("duhl ("), std::string::npos) << monitor.log();
}

// A peer's report listing more robots than the wire contract's bound (DIAGNOSTICS_MAX_ROBOTS) is
// refused and counted by a localizer, not taken in part.
TEST_F(Monitor, ALocalizerRefusesAPeerReportListingMoreRobotsThanTheBound) {
  const std::string name = "beaconloc.localizer.range_ekf";
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  dds::Participant bus(dds_, "test.fake_localizer");
  auto writer = bus.writer<msg::DiagnosticsPubSubType>(dds::kDiagnosticsTopic);
  ASSERT_TRUE(wait_until([&] { return diagnostics.latest().count(name) == 1; }, 15s)) << localizer.log();
  msg::Diagnostics d;
  d.participant("test.fake_localizer");
  for (std::uint32_t i = 0; i <= msg::DIAGNOSTICS_MAX_ROBOTS; ++i)
    d.robots_localized().push_back("r" + std::to_string(i));
  ASSERT_TRUE(writer->write(&d));
  ASSERT_TRUE(wait_until(
      [&] { return rejected_count(diagnostics.latest().at(name), "diagnostics.too_many_robots") == 1; }, 15s))
      << localizer.log();
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(localizer, "localizer"));
}

// Item 12 of issue 23: the monitor kept (and copied each second) every pose. Without --truth or
// --out it keeps the newest of each robot: one stored pose per robot after 900 poses, the counts
// exact; recording every pose (scoring) keeps all of them, a correction replacing its pose. A
// non-finite pose is refused by both, and counted.
TEST_F(Monitor, TheRecorderKeepsOnePosePerRobotUnlessItRecordsEveryPose) {
  PoseRecorder newest(dds_, PoseRecorder::Keep::kNewestPerRobot);
  PoseRecorder every(dds_, PoseRecorder::Keep::kEveryPose);
  dds::Participant bus(dds_, "test.localizer");
  auto writer = bus.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic);
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
  for (const auto& p : newest.poses()) EXPECT_TRUE(publishable(p.row.estimate));
  std::size_t corrected = 0;
  for (const auto& p : every.poses()) {
    EXPECT_TRUE(publishable(p.row.estimate));
    corrected += p.row.estimate.pose_map_base.x() == 42.0;
  }
  EXPECT_EQ(corrected, 1u);
}

// The monitor with --out writes every pose it got, and neither its lines nor the file carry a
// non-finite number: a pose with one is refused and counted (even as the newest of its robot).
TEST_F(Monitor, WithOutTheMonitorWritesEveryPoseAndNoNonFiniteNumber) {
  ChildProcess monitor(command("monitor", {"--out", path("poses.csv")}), path("monitor.log"));
  dds::Participant bus(dds_, "test.localizer");
  auto writer = bus.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic);
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
  for (const auto& r : rows) EXPECT_TRUE(publishable(r.estimate)) << r.robot_id << ' ' << r.estimate.stamp_ns;
}

// monitor --truth with poses of which none lies where the truth has a stamp: "not scored", and a
// failure (exit 1), as `run` fails; never a 0 m figure, never success.
TEST_F(Monitor, WithTruthThatCoversNoPoseItScoresNothingAndFails) {
  {
    std::ofstream truth(path("truth.csv"));
    truth << "stamp_ns,x_m,y_m,yaw_rad\n";
    for (int i = 0; i < 100; ++i) truth << (1000 + i) * kNsPerSecond << ",0,0,0\n";  // 1000 s on
  }
  ChildProcess monitor(command("monitor", {"--truth", path("truth.csv")}), path("monitor.log"));
  dds::Participant bus(dds_, "test.localizer");
  auto writer = bus.writer<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic);
  ASSERT_TRUE(dds::wait_for_matched_readers({writer}, scaled(15s))) << monitor.log();
  std::vector<msg::PoseEstimate> sent;
  for (int i = 1; i <= 50; ++i) sent.push_back(pose("ra", i * 10 * kNsPerMillisecond, 0.01 * i));
  ASSERT_NO_FATAL_FAILURE(write_acknowledged(writer, sent));
  ASSERT_TRUE(wait_until([&] { return monitor.log().find("ra test_estimator: 50 poses") != std::string::npos; }, 15s))
      << monitor.log();
  monitor.signal(SIGTERM);
  const auto code = monitor.wait(20s);
  ASSERT_TRUE(code) << monitor.log();
  EXPECT_EQ(*code, 1) << monitor.log();
  EXPECT_NE(monitor.log().find("not scored"), std::string::npos) << monitor.log();
  EXPECT_EQ(monitor.log().find("RMS"), std::string::npos) << monitor.log();
}

}  // namespace
}  // namespace beaconloc::testing
