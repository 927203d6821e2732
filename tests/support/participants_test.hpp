#pragma once
// A test that runs beaconloc participants as processes: a temporary directory of its own (logs,
// truth files), a DDS domain no other run on this machine holds, the participants' command
// lines on it, and a clean stop. The integration fixtures derive from it.
#include <beaconloc.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "beaconloc/dds/participant.hpp"
#include "diagnostics_recorder.hpp"
#include "domain_id.hpp"
#include "pose_recorder.hpp"
#include "process.hpp"

namespace beaconloc::testing {

// The names the participants report under (their Diagnostics): `beaconloc decoder` and
// `beaconloc localizer` with its default estimator.
inline const std::string kDecoder = "beaconloc.decoder";
inline const std::string kRangeEkfLocalizer = "beaconloc.localizer.range_ekf";

// The stamp of a gateway's last odometry sample: the last row of its truth file (--truth-out,
// complete once the gateway has exited).
inline StampNs last_truth_stamp_ns(const std::string& truth_csv) {
  const TruthTrack truth = load_truth_csv(truth_csv);
  return truth.size() ? truth.samples().rbegin()->first : 0;
}

// Waits until a pose of `robot` at or after stamp_ns has been recorded: the pipeline has
// drained up to it. False on timeout (scaled() by kTimeScale).
inline bool wait_for_pose(const PoseRecorder& recorder, const std::string& robot, StampNs stamp_ns,
                          std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
  return eventually(
      [&] {
        // Cheap first (the newest pose of any robot), not a copy of every pose each time.
        if (recorder.newest_stamp_ns() < stamp_ns) return false;
        const auto poses = recorder.poses();
        return std::any_of(poses.begin(), poses.end(), [&](const RecordedPose& p) {
          return p.row.robot_id == robot && p.row.estimate.stamp_ns >= stamp_ns;
        });
      },
      timeout);
}

// Waits until `robot` has been localized over `span` of its own time: its first pose, then one
// `span` later by stamp, for a gateway that runs until the test stops it. How long the localizer
// took to start and find the robot costs no pose span. False on timeout (scaled() by kTimeScale):
// `first_pose` for the first pose, then the span plus `first_pose` for the rest.
inline bool wait_for_pose_span(const PoseRecorder& recorder, const std::string& robot,
                               std::chrono::milliseconds span,
                               std::chrono::milliseconds first_pose = std::chrono::seconds(30)) {
  StampNs first_ns = 0;
  const bool localized = eventually(
      [&] {
        for (const auto& p : recorder.poses()) {
          if (p.row.robot_id == robot) {
            first_ns = p.row.estimate.stamp_ns;
            return true;
          }
        }
        return false;
      },
      first_pose);
  return localized &&
         wait_for_pose(recorder, robot, first_ns + span.count() * kNsPerMillisecond, span + first_pose);
}

// Poses per second of the poses' own stamps (the gateway's odometry clock), not of their arrival:
// how completely the localizer kept up, whatever bunching a loaded machine gave the deliveries.
// The poses of one robot; 0 for fewer than two.
inline double stamp_rate_hz(const std::vector<RecordedPose>& poses) {
  if (poses.size() < 2) return 0.0;
  const auto [first, last] = std::minmax_element(
      poses.begin(), poses.end(),
      [](const auto& a, const auto& b) { return a.row.estimate.stamp_ns < b.row.estimate.stamp_ns; });
  const double span_s = ns_to_s(last->row.estimate.stamp_ns - first->row.estimate.stamp_ns);
  return span_s > 0.0 ? static_cast<double>(poses.size() - 1) / span_s : 0.0;
}

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
  // Waits for a gateway to end its run, then for the pipeline to drain: the localizer's pose of
  // `robot` at the run's last odometry stamp (the last row of the truth file the gateway wrote;
  // the odometry is reliable, its newest sample always arrives).
  static void finish_gateway(ChildProcess& gateway, const PoseRecorder& recorder, const std::string& robot,
                             const std::string& truth_csv) {
    const auto code = gateway.wait(std::chrono::seconds(90));
    ASSERT_TRUE(code) << "gateway did not finish";
    EXPECT_EQ(*code, 0) << gateway.log();
    EXPECT_TRUE(wait_for_pose(recorder, robot, last_truth_stamp_ns(truth_csv)))
        << robot << ": no pose at the run's last odometry stamp";
  }
  // Stops a gateway that runs until stopped (--duration-s 0), then waits for the pipeline to drain
  // as finish_gateway does.
  static void stop_gateway(ChildProcess& gateway, const PoseRecorder& recorder, const std::string& robot,
                           const std::string& truth_csv) {
    ASSERT_NO_FATAL_FAILURE(stop_cleanly(gateway, "gateway"));
    EXPECT_TRUE(wait_for_pose(recorder, robot, last_truth_stamp_ns(truth_csv)))
        << robot << ": no pose at the run's last odometry stamp";
  }

  DomainLease domain_;
  dds::DdsOptions dds_;
  std::string dir_;
};

// Waits until the newest Diagnostics of participant `name` satisfies pred, or the timeout (scaled()
// by kTimeScale) passes; returns the newest one seen either way (a default one if it never
// reported), so that the caller's expectations show what was there.
template <class Pred>
msg::Diagnostics wait_for_diagnostics(const DiagnosticsRecorder& recorder, const std::string& name, Pred pred,
                                      std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
  msg::Diagnostics newest;
  eventually(
      [&] {
        const auto latest = recorder.latest();
        const auto it = latest.find(name);
        if (it == latest.end()) return false;
        newest = it->second;
        return static_cast<bool>(pred(newest));
      },
      timeout);
  return newest;
}

// Waits until every participant named has reported once: it runs, its readers and writers
// exist (they are created before its DiagnosticsPublisher). A test starts what feeds them only
// then, however slowly they started. False on timeout (scaled() by kTimeScale).
inline bool wait_until_reporting(const DiagnosticsRecorder& recorder,
                                 std::initializer_list<std::string> names,
                                 std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
  return eventually(
      [&] {
        const auto latest = recorder.latest();
        for (const auto& name : names) {
          if (!latest.count(name)) return false;
        }
        return true;
      },
      timeout);
}

// How many samples a participant's Diagnostics counts as refused for `reason` (0 when none).
inline std::uint64_t rejected_count(const msg::Diagnostics& d, const std::string& reason) {
  for (const auto& r : d.rejected()) {
    if (r.reason() == reason) return r.count();
  }
  return 0;
}

}  // namespace beaconloc::testing
