// gateway, decoder and localizer as three processes on loopback, on a DDS domain of the run's
// own; this test process records the poses and compares them with the gateway's ground truth.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <thread>

#include "diagnostics_recorder.hpp"
#include "domain_id.hpp"
#include "participants_test.hpp"
#include "pose_recorder.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class Pipeline : public ParticipantsTest {
 protected:
  // Waits for the gateway to finish its run, lets the last samples through, stops the others.
  static void finish_run(ChildProcess& gateway, ChildProcess& decoder, ChildProcess& localizer) {
    const auto gateway_code = gateway.wait(90s);
    ASSERT_TRUE(gateway_code) << "gateway did not finish";
    EXPECT_EQ(*gateway_code, 0) << gateway.log();
    std::this_thread::sleep_for(500ms);
    stop_cleanly(decoder, "decoder");
    stop_cleanly(localizer, "localizer");
  }
};

TEST_F(Pipeline, ThreeProcessesLocalizeAtOdometryRate) {
  PoseRecorder recorder(dds_);
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  std::this_thread::sleep_for(1s);  // let the late processes' readers appear first
  ChildProcess gateway(command("gateway", {"--robot", "robot7", "--duration-s", "25", "--seed", "5",
                                           "--truth-out", path("truth.csv")}),
                       path("gateway.log"));
  ASSERT_NO_FATAL_FAILURE(finish_run(gateway, decoder, localizer));

  const auto poses = recorder.poses();
  ASSERT_GT(poses.size(), 100u) << "localizer log:\n" << localizer.log();
  for (const auto& p : poses) ASSERT_EQ(p.row.robot_id, "robot7");
  const auto truth = load_truth_csv(path("truth.csv"));
  const PoseRunSummary s = summarize(poses, truth);
  const double stamp_span_s =
      ns_to_s(poses.back().row.estimate.stamp_ns - poses.front().row.estimate.stamp_ns);
  const double first_pose_s = ns_to_s(poses.front().row.estimate.stamp_ns - truth.samples().begin()->first);
  std::printf(
      "multi-process pipeline: first pose %.2f s into the run; %zu poses over %.1f s of motion at %.1f Hz; "
      "position RMS %.3f m, max %.3f m; heading RMS %.2f deg\n",
      first_pose_s, s.poses, stamp_span_s, s.pose_rate_hz, s.metrics.position_rms_m, s.metrics.position_max_m,
      s.metrics.heading_rms_deg.value_or(-1));
  EXPECT_GE(stamp_span_s, 20.0);  // localized over >= 20 s of motion
  EXPECT_GE(s.pose_rate_hz, 90.0);
  EXPECT_EQ(s.metrics.samples_without_truth, 0u);
  EXPECT_LE(s.metrics.position_rms_m, 0.15);

  // Every participant reports what it accepted and refused, by reason.
  const auto latest = diagnostics.latest();
  print_diagnostics(diagnostics.reports(), std::cout);
  ASSERT_EQ(latest.count("beaconloc.gateway.robot7"), 1u);
  ASSERT_EQ(latest.count("beaconloc.decoder"), 1u);
  ASSERT_EQ(latest.count("beaconloc.localizer.range_ekf"), 1u);
  const auto& decoder_diag = latest.at("beaconloc.decoder");
  EXPECT_GT(decoder_diag.accepted(), 250u);      // 15 TOF/s for > 20 s, less the last second
  EXPECT_TRUE(decoder_diag.rejected().empty());  // the simulated source sends no bad TOF
  EXPECT_GT(latest.at("beaconloc.localizer.range_ekf").accepted(), 1500u);
}

TEST_F(Pipeline, LateJoiningLocalizerGetsTheMapAndLocalizes) {
  ChildProcess gateway(command("gateway", {"--robot", "late", "--duration-s", "20", "--seed", "6",
                                           "--truth-out", path("truth.csv")}),
                       path("gateway.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  std::this_thread::sleep_for(5s);  // the beacon map was written 5 s ago, once
  PoseRecorder recorder(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  ASSERT_NO_FATAL_FAILURE(finish_run(gateway, decoder, localizer));

  const auto poses = recorder.poses();
  ASSERT_GT(poses.size(), 100u) << "localizer log:\n" << localizer.log();
  const auto truth = load_truth_csv(path("truth.csv"));
  const PoseRunSummary s = summarize(poses, truth);
  const double stamp_span_s =
      ns_to_s(poses.back().row.estimate.stamp_ns - poses.front().row.estimate.stamp_ns);
  std::printf("late-joining localizer: %zu poses over %.1f s at %.1f Hz; position RMS %.3f m\n", s.poses,
              stamp_span_s, s.pose_rate_hz, s.metrics.position_rms_m);
  // Started 5 s into a 20 s run: localizing within ~3 s of its start leaves >= 12 s of poses.
  EXPECT_GE(stamp_span_s, 12.0);
  EXPECT_EQ(s.metrics.samples_without_truth, 0u);
  EXPECT_GE(s.pose_rate_hz, 90.0);
  EXPECT_LE(s.metrics.position_rms_m, 0.15);
}

TEST_F(Pipeline, TwoRobotsShareTheTopicsWithoutCrosstalk) {
  PoseRecorder recorder(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  std::this_thread::sleep_for(1s);
  ChildProcess second(command("gateway", {"--robot", "beta", "--duration-s", "15", "--seed", "8",
                                          "--truth-out", path("beta.csv")}),
                      path("beta.log"));
  std::this_thread::sleep_for(3s);  // alpha drives the same loop 3 s (1 m) behind beta
  ChildProcess first(command("gateway", {"--robot", "alpha", "--duration-s", "15", "--seed", "7",
                                         "--truth-out", path("alpha.csv")}),
                     path("alpha.log"));
  const auto second_code = second.wait(90s);
  ASSERT_TRUE(second_code);
  EXPECT_EQ(*second_code, 0) << second.log();
  ASSERT_NO_FATAL_FAILURE(finish_run(first, decoder, localizer));

  std::map<std::string, std::vector<RecordedPose>> by_robot;
  for (const auto& p : recorder.poses()) by_robot[p.row.robot_id].push_back(p);
  ASSERT_EQ(by_robot.size(), 2u);
  for (const auto& robot : {"alpha", "beta"}) {
    const TruthTrack truth = load_truth_csv(path(std::string(robot) + ".csv"));
    const PoseRunSummary s = summarize(by_robot[robot], truth);
    // Poses are stamped with the robot's own odometry stamps: each must match one exactly.
    for (const auto& p : by_robot[robot]) ASSERT_TRUE(truth.at(p.row.estimate.stamp_ns, 0)) << robot;
    std::printf("%s: %zu poses at %.1f Hz, position RMS %.3f m\n", robot, s.poses, s.pose_rate_hz,
                s.metrics.position_rms_m);
    EXPECT_GT(s.poses, 1000u) << robot;
    EXPECT_LE(s.metrics.position_rms_m, 0.15) << robot;
  }
}

}  // namespace
}  // namespace beaconloc::testing
