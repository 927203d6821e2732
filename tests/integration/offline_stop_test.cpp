// The offline commands (accuracy, eval) hold no DDS entity and poll no stop flag: a stop signal
// ends them at once (the default action), instead of being taken as a clean-stop request that
// nothing reads, which left `accuracy` running for minutes after Ctrl-C (issue 23).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <thread>

#include "participants_test.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

class OfflineStop : public ParticipantsTest {};

TEST_F(OfflineStop, AnAccuracySweepEndsAtOnceOnASignal) {
  for (int sig : {SIGINT, SIGTERM}) {
    // 1000 seeds of the default scenario: minutes of work.
    ChildProcess accuracy({BEACONLOC_EXECUTABLE, "accuracy", "--scenario",
                           std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/default.yaml", "--seeds", "1000"},
                          path("accuracy.log"));
    std::this_thread::sleep_for(500ms);  // whether it is loading or sweeping, it must stop
    const auto sent = std::chrono::steady_clock::now();
    accuracy.signal(sig);
    const auto code = accuracy.wait(5s);
    ASSERT_TRUE(code) << "signal " << sig << ": still running 5 s after it\n" << accuracy.log();
    EXPECT_EQ(*code, 128 + sig) << accuracy.log();
    std::printf("accuracy, signal %d: ended after %.2f s\n", sig,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count());
  }
}

}  // namespace
}  // namespace beaconloc::testing
