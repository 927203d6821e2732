#pragma once
// A test that runs beaconloc participants as processes: a temporary directory of its own (logs,
// truth files), a DDS domain no other run on this machine holds, the participants' command
// lines on it, and a clean stop. The integration fixtures derive from it.
#include <beaconloc.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "beaconloc/dds/participant.hpp"
#include "domain_id.hpp"
#include "process.hpp"

namespace beaconloc::testing {

class ParticipantsTest : public ::testing::Test {
 protected:
  explicit ParticipantsTest(std::string participant_profile = "beaconloc.loopback") {
    dds_.domain_id = domain_.id();
    dds_.participant_profile = std::move(participant_profile);
  }
  void SetUp() override {
    char dir[] = "/tmp/beaconloc-test-XXXXXX";
    ASSERT_NE(::mkdtemp(dir), nullptr);
    dir_ = dir;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // `beaconloc <sub>` on this test's domain and participant profile, then `extra`.
  std::vector<std::string> command(const std::string& sub, std::vector<std::string> extra = {}) const {
    std::vector<std::string> argv{
        BEACONLOC_EXECUTABLE,    sub, "--domain", std::to_string(domain_.id()), "--participant-profile",
        dds_.participant_profile};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }

  // Stops a participant the way an operator does, and expects a clean exit.
  static void stop_cleanly(ChildProcess& p, const char* name) {
    p.signal(SIGTERM);
    const auto code = p.wait(std::chrono::seconds(15));
    ASSERT_TRUE(code) << name << " did not stop on SIGTERM";
    EXPECT_EQ(*code, 0) << name << " log:\n" << p.log();
  }

  DomainLease domain_;
  dds::DdsOptions dds_;
  std::string dir_;
};

// How many samples a participant's Diagnostics counts as refused for `reason` (0 when none).
inline std::uint64_t rejected_count(const msg::Diagnostics& d, const std::string& reason) {
  for (const auto& r : d.rejected()) {
    if (r.reason() == reason) return r.count();
  }
  return 0;
}

}  // namespace beaconloc::testing
