// A participant whose peers died says so in its status (issue 23): the localizer when the
// decoder is killed, the bridge when the localizer is.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "diagnostics_recorder.hpp"
#include "participants_test.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class PeerLoss : public ParticipantsTest {
 protected:
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

}  // namespace
}  // namespace beaconloc::testing
