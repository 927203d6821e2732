// A gateway paced slower than real time sleeps between its steps; a stop (SIGINT, SIGTERM) must
// end it at once whatever it was to sleep, and a speed outside the bounds is refused at start
// with the option named (issue 23, item 10).
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "diagnostics_recorder.hpp"
#include "participants_test.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class GatewayStop : public ParticipantsTest {};

TEST_F(GatewayStop, ASlowGatewayStopsAtOnceOnASignal) {
  DiagnosticsRecorder diagnostics(dds_);
  int run = 0;
  for (const char* speed : {"0.002", "0.001"}) {
    for (int sig : {SIGTERM, SIGINT}) {
      // A robot id of its own per run: the Diagnostics seen are this process's, not the last one's.
      const std::string robot = "slow" + std::to_string(++run);
      ChildProcess gateway(command("gateway", {"--speed", speed, "--robot", robot}), path(robot + ".log"));
      // Started: its Diagnostics are on the bus (it then sleeps 5-10 s per 10 ms step).
      const auto end = std::chrono::steady_clock::now() + scaled(15s);
      while (!diagnostics.latest().count("beaconloc.gateway." + robot) &&
             std::chrono::steady_clock::now() < end) {
        std::this_thread::sleep_for(50ms);
      }
      ASSERT_TRUE(diagnostics.latest().count("beaconloc.gateway." + robot)) << gateway.log();
      std::this_thread::sleep_for(200ms);  // into its first long wait
      const auto sent = std::chrono::steady_clock::now();
      gateway.signal(sig);
      const auto code = gateway.wait(10s);
      ASSERT_TRUE(code) << "--speed " << speed << ": the gateway did not stop on signal " << sig;
      EXPECT_EQ(*code, 0) << gateway.log();
      std::printf("--speed %s, signal %d: stopped after %.2f s\n", speed, sig,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count());
    }
  }
}

TEST_F(GatewayStop, SpeedsBeyondTheBoundsAreRefusedWithTheOptionNamed) {
  for (const char* speed : {"1e-300", "1e-10", "0.0009", "1e5", "-1", "nan", "inf"}) {
    const auto [code, out] = run_command(command("gateway", {"--speed", speed, "--duration-s", "1"}), 20s);
    EXPECT_NE(code, 0) << speed << "\n" << out;
    EXPECT_NE(out.find("--speed"), std::string::npos) << speed << "\n" << out;
  }
}

}  // namespace
}  // namespace beaconloc::testing
