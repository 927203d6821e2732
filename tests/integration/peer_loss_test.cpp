// A participant whose peers died says so in its status (issue 23): the localizer when the
// decoder is killed or the gateway hangs, the bridge when the localizer is.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "diagnostics_recorder.hpp"
#include "participants_test.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

// UDP on loopback alone: a participant killed with SIGKILL cannot remove its shared-memory
// segments and port files from /dev/shm.
class PeerLoss : public ParticipantsTest {
 protected:
  PeerLoss() : ParticipantsTest("beaconloc.loopback_udp") {}
  static bool says(const msg::Diagnostics& d, const std::string& text) {
    return d.message().find(text) != std::string::npos;
  }
};

TEST_F(PeerLoss, TheLocalizerSaysItsDecoderDiedAndTheBridgeItsLocalizer) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess gateway(command("gateway"), path("gateway.log"));
  auto decoder = std::make_unique<ChildProcess>(command("decoder"), path("decoder.log"));
  auto localizer = std::make_unique<ChildProcess>(command("localizer"), path("localizer.log"));
  ChildProcess bridge(command("bridge"), path("bridge.log"));
  const auto live = wait_for_diagnostics(
      diagnostics, "beaconloc.bridge.robot1",
      [](const msg::Diagnostics& d) { return d.status() == msg::PARTICIPANT_STATUS_OK; });
  ASSERT_EQ(live.status(), msg::PARTICIPANT_STATUS_OK) << live.message() << "\n" << localizer->log();

  decoder->signal(SIGKILL);  // dies without leaving: only its lapsed liveliness tells
  decoder->wait(10s);
  const auto orphaned = wait_for_diagnostics(
      diagnostics, "beaconloc.localizer.range_ekf",
      [](const msg::Diagnostics& d) { return says(d, "no live range writer: the decoder was lost"); });
  EXPECT_TRUE(says(orphaned, "no live range writer: the decoder was lost")) << orphaned.message();
  EXPECT_EQ(orphaned.status(), msg::PARTICIPANT_STATUS_DEGRADED);

  stop_cleanly(*localizer, "localizer");
  const auto silent = wait_for_diagnostics(
      diagnostics, "beaconloc.bridge.robot1",
      [](const msg::Diagnostics& d) { return says(d, "the localizer is gone or silent"); });
  EXPECT_TRUE(says(silent, "the localizer is gone or silent")) << silent.message();
  EXPECT_EQ(silent.status(), msg::PARTICIPANT_STATUS_DEGRADED);
  stop_cleanly(bridge, "bridge");
  stop_cleanly(gateway, "gateway");
}

// A gateway that is alive but sends no odometry (hung in its run loop, or paced far slower than
// real time: its liveliness is asserted by a task of its own) is told by the odometry's deadline
// alone: the localizer reports the robot's odometry silent and is degraded.
TEST_F(PeerLoss, TheLocalizerSaysWhenALiveGatewaySendsNoOdometry) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  wait_for_diagnostics(diagnostics, "beaconloc.localizer.range_ekf", [](const msg::Diagnostics&) { return true; });
  // A step now and then, 10 s of wall time per 10 ms odometry period: alive, and silent.
  ChildProcess gateway(command("gateway", {"--speed", "0.001"}), path("gateway.log"));
  const auto silent = wait_for_diagnostics(diagnostics, "beaconloc.localizer.range_ekf", [](const msg::Diagnostics& d) {
    return says(d, "no odometry within its deadline");
  });
  EXPECT_TRUE(says(silent, "no odometry within its deadline for 1 robot(s), first robot1")) << silent.message();
  EXPECT_EQ(silent.status(), msg::PARTICIPANT_STATUS_DEGRADED);
  EXPECT_FALSE(says(silent, "the gateway was lost")) << silent.message();  // it is alive
  stop_cleanly(localizer, "localizer");
  stop_cleanly(gateway, "gateway");
}

}  // namespace
}  // namespace beaconloc::testing
