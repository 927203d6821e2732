// gateway, decoder and localizer as three processes on loopback, on a DDS domain of the run's
// own; this test process records the poses and compares them with the gateway's ground truth.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>

#include "diagnostics_recorder.hpp"
#include "domain_id.hpp"
#include "participants_test.hpp"
#include "pose_recorder.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class Pipeline : public ParticipantsTest {};

// What a gateway has written after 3 s of its run: 100 odometry samples and 15 TOFs a second.
constexpr std::uint64_t kBetaAhead = 3 * (100 + 15);

TEST_F(Pipeline, ThreeProcessesLocalizeAtOdometryRate) {
  PoseRecorder recorder(dds_);
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  // Their readers exist before the gateway writes, however slowly they started.
  ASSERT_TRUE(wait_until_reporting(diagnostics, {kDecoder, kRangeEkfLocalizer}))
      << decoder.log() << localizer.log();
  // Runs until the robot has been localized over 20 s of its time, however long discovery took.
  ChildProcess gateway(command("gateway", {"--robot", "robot7", "--duration-s", "0", "--seed", "5",
                                           "--truth-out", path("truth.csv")}),
                       path("gateway.log"));
  ASSERT_TRUE(wait_for_pose_span(recorder, "robot7", 20s))
      << localizer.log() << decoder.log() << gateway.log();
  ASSERT_NO_FATAL_FAILURE(stop_gateway(gateway, recorder, "robot7", path("truth.csv")));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(decoder, "decoder"));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(localizer, "localizer"));

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
      first_pose_s, s.poses, stamp_span_s, stamp_rate_hz(poses), s.metrics.position_rms_m,
      s.metrics.position_max_m, s.metrics.heading_rms_deg.value_or(-1));
  EXPECT_GE(stamp_span_s, 20.0);          // localized over >= 20 s of motion
  EXPECT_GE(stamp_rate_hz(poses), 90.0);  // a pose for (nearly) every odometry sample
  EXPECT_EQ(s.metrics.samples_without_truth, 0u);
  EXPECT_LE(s.metrics.position_rms_m, 0.15);

  // Every participant reports what it accepted and refused, by reason.
  const auto latest = diagnostics.latest();
  print_diagnostics(diagnostics.reports(), std::cout);
  ASSERT_EQ(latest.count("beaconloc.gateway.robot7"), 1u);
  ASSERT_EQ(latest.count(kDecoder), 1u);
  ASSERT_EQ(latest.count(kRangeEkfLocalizer), 1u);
  const auto& decoder_diag = latest.at(kDecoder);
  EXPECT_GT(decoder_diag.accepted(), 250u);      // 15 TOF/s for > 20 s, less the last second
  EXPECT_TRUE(decoder_diag.rejected().empty());  // the simulated source sends no bad TOF
  EXPECT_GT(latest.at(kRangeEkfLocalizer).accepted(), 1500u);
}

TEST_F(Pipeline, LateJoiningLocalizerGetsTheMapAndLocalizes) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess gateway(command("gateway", {"--robot", "late", "--duration-s", "0", "--seed", "6",
                                           "--truth-out", path("truth.csv")}),
                       path("gateway.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  // The localizer joins >= 4 s into the run, long after the gateway wrote the beacon map, once:
  // when the decoder (which needs that map) has decoded 4 s of TOFs (15 a second), counted from
  // the run's progress, not from when this test started the gateway.
  const auto decoding = wait_for_diagnostics(diagnostics, kDecoder,
                                             [](const msg::Diagnostics& d) { return d.accepted() >= 60; });
  ASSERT_GE(decoding.accepted(), 60u) << decoder.log() << gateway.log();
  PoseRecorder recorder(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  // The run goes on until the late localizer has localized over 12 s, however long it took to start.
  ASSERT_TRUE(wait_for_pose_span(recorder, "late", 12s)) << localizer.log() << decoder.log() << gateway.log();
  ASSERT_NO_FATAL_FAILURE(stop_gateway(gateway, recorder, "late", path("truth.csv")));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(decoder, "decoder"));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(localizer, "localizer"));

  const auto poses = recorder.poses();
  ASSERT_GT(poses.size(), 100u) << "localizer log:\n" << localizer.log();
  const auto truth = load_truth_csv(path("truth.csv"));
  const PoseRunSummary s = summarize(poses, truth);
  const double stamp_span_s =
      ns_to_s(poses.back().row.estimate.stamp_ns - poses.front().row.estimate.stamp_ns);
  std::printf("late-joining localizer: %zu poses over %.1f s at %.1f Hz; position RMS %.3f m\n", s.poses,
              stamp_span_s, stamp_rate_hz(poses), s.metrics.position_rms_m);
  EXPECT_GE(stamp_span_s, 12.0);
  EXPECT_EQ(s.metrics.samples_without_truth, 0u);
  EXPECT_GE(stamp_rate_hz(poses), 90.0);  // a pose for (nearly) every odometry sample
  EXPECT_LE(s.metrics.position_rms_m, 0.15);
}

TEST_F(Pipeline, TwoRobotsShareTheTopicsWithoutCrosstalk) {
  PoseRecorder recorder(dds_);
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  ASSERT_TRUE(wait_until_reporting(diagnostics, {kDecoder, kRangeEkfLocalizer}))
      << decoder.log() << localizer.log();
  ChildProcess second(command("gateway", {"--robot", "beta", "--duration-s", "15", "--seed", "8",
                                          "--truth-out", path("beta.csv")}),
                      path("beta.log"));
  // alpha drives the same loop >= 3 s (1 m) behind beta, so that poses mixed up between the
  // robots would show as errors: it starts once beta has written 3 s of samples (odometry at
  // 100 Hz, 15 TOFs a second; the beacon map), by beta's own count, however slowly beta started.
  const auto beta_ahead =
      wait_for_diagnostics(diagnostics, "beaconloc.gateway.beta",
                           [](const msg::Diagnostics& d) { return d.accepted() >= kBetaAhead; });
  ASSERT_GE(beta_ahead.accepted(), kBetaAhead) << second.log();
  ChildProcess first(command("gateway", {"--robot", "alpha", "--duration-s", "15", "--seed", "7",
                                         "--truth-out", path("alpha.csv")}),
                     path("alpha.log"));
  ASSERT_NO_FATAL_FAILURE(finish_gateway(second, recorder, "beta", path("beta.csv")));
  ASSERT_NO_FATAL_FAILURE(finish_gateway(first, recorder, "alpha", path("alpha.csv")));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(decoder, "decoder"));
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(localizer, "localizer"));

  std::map<std::string, std::vector<RecordedPose>> by_robot;
  for (const auto& p : recorder.poses()) by_robot[p.row.robot_id].push_back(p);
  ASSERT_EQ(by_robot.size(), 2u);
  for (const auto& robot : {"alpha", "beta"}) {
    const TruthTrack truth = load_truth_csv(path(std::string(robot) + ".csv"));
    const PoseRunSummary s = summarize(by_robot[robot], truth);
    // Poses are stamped with the robot's own odometry stamps: each must match one exactly.
    for (const auto& p : by_robot[robot]) ASSERT_TRUE(truth.at(p.row.estimate.stamp_ns, 0)) << robot;
    std::printf("%s: %zu poses at %.1f Hz, position RMS %.3f m\n", robot, s.poses,
                stamp_rate_hz(by_robot[robot]), s.metrics.position_rms_m);
    EXPECT_GT(s.poses, 1000u) << robot;
    EXPECT_LE(s.metrics.position_rms_m, 0.15) << robot;
  }
}

}  // namespace
}  // namespace beaconloc::testing
