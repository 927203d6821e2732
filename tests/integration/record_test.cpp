// Recording a run and replaying it (docs/replay-format.md, "Recordings of the bus"): a run's own
// recording and `beaconloc record`'s, each replayed to byte-identical estimates; the recorder's
// rosbag2 bag read by a reader that is not the writer (tests/tools/check_rosbag2.py), field by
// field for poses and odometry against what the ROS 2 conventions make of the recorded poses
// (tests/tools/ros2_expected_from_recording.py); and a recorder killed mid-run, its recording read
// back whole.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "domain_id.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

const std::string kTools = std::string(BEACONLOC_SOURCE_DIR) + "/tests/tools/";
// The built-in scenario's receivers, exactly as its simulator computes them.
const std::string kReceivers =
    "0.19:0,-0.09499999999999996:0.16454482671904336,-0.09500000000000008:-0.1645448267190433";
// The built-in scenario's settings a replay is not told by the recording (its decoder's limits and
// noise, the robot's start): given as a user replaying it would.
const std::vector<std::string> kReplaySettings{
    "--min-range-m", "0", "--max-range-m", "5", "--range-sigma-m", "0.01", "--initial-pose", "0.5", "0", "0"};

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The rows of a CSV with only its first `columns` columns (a run's recording adds the simulator's
// hidden truth to its TOF rows; the bus does not carry it).
std::string first_columns(const std::string& text, int columns) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    std::istringstream cells(line);
    std::string cell;
    for (int c = 0; c < columns && std::getline(cells, cell, ','); ++c) out += (c ? "," : "") + cell;
    out += '\n';
  }
  return out;
}

std::size_t lines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

class Recording : public ::testing::Test {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/beaconloc-record-XXXXXX";
    ASSERT_NE(::mkdtemp(dir), nullptr);
    dir_ = dir;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::vector<std::string> beaconloc(const std::string& sub, std::vector<std::string> args) const {
    args.insert(args.begin(), {BEACONLOC_EXECUTABLE, sub, "--domain", std::to_string(domain_.id())});
    return args;
  }
  std::pair<int, std::string> run(std::vector<std::string> args) {
    return run_command(beaconloc("run", args), 300s);
  }
  std::pair<int, std::string> replay(const std::string& recording, const std::string& out) {
    std::vector<std::string> args{"--replay", recording, "--speed", "4", "--out", out};
    args.insert(args.end(), kReplaySettings.begin(), kReplaySettings.end());
    return run(args);
  }
  std::pair<int, std::string> python(std::vector<std::string> args) {
    args.insert(args.begin(), BEACONLOC_SYSTEM_PYTHON3);
    return run_command(args, 120s);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  DomainLease domain_;
  std::string dir_;
};

TEST_F(Recording, ARunsOwnRecordingReplaysToByteIdenticalEstimates) {
  // Paced at four times real time, live and replayed: flat out on a loaded machine (the whole
  // suite on 2 cores, seen once), a sample can reach the localizer beyond its horizon in one run
  // and not the other (refused and counted, core/out_of_sequence_fusion.hpp), and the estimates
  // then differ for that reason, not the recording's.
  const auto [code, out] = run({"--duration-s", "8", "--seed", "3", "--speed", "4", "--out", path("live")});
  ASSERT_EQ(code, 0) << out;
  const auto [replay_code, replay_out] = replay(path("live"), path("replayed"));
  ASSERT_EQ(replay_code, 0) << replay_out;
  const std::string live = read(path("live/estimate.csv"));
  EXPECT_GT(lines(live), 700u);
  EXPECT_EQ(read(path("replayed/estimate.csv")), live) << "the replay's estimates differ from the live run's";
  // The replay scored against the run's truth, which the recording holds.
  EXPECT_NE(replay_out.find("against ground truth"), std::string::npos) << replay_out;
}

TEST_F(Recording, TheRecorderHearsARunFromItsStartAndItsRecordingAndBagHoldWhatWasSent) {
  ChildProcess recorder(beaconloc("record", {"--out", path("rec"), "--receivers", kReceivers}),
                        path("record.log"));
  // The run waits for one reader besides its own on TOFs and odometry: the recorder's. Paced at
  // twice real time, so that a recorder in another process keeps up on a loaded machine (the
  // writers' histories are finite: a reader that falls behind loses samples).
  const auto [code, out] = run({"--duration-s", "8", "--seed", "3", "--speed", "2", "--bridge",
                                "--wait-for-readers", "1", "--out", path("live")});
  ASSERT_EQ(code, 0) << out;
  std::this_thread::sleep_for(1s);  // the last samples on their way to the recorder
  recorder.signal(SIGTERM);
  const auto recorded = recorder.wait(30s);
  ASSERT_TRUE(recorded);
  ASSERT_EQ(*recorded, 0) << recorder.log();

  // Every sample the gateway published, as it published it.
  EXPECT_EQ(read(path("rec/odometry.csv")), read(path("live/odometry.csv")));
  EXPECT_EQ(read(path("rec/tof.csv")), first_columns(read(path("live/tof.csv")), 6));
  // Replayed, the recorder's recording gives the live run's estimates, byte for byte.
  const auto [replay_code, replay_out] = replay(path("rec"), path("replayed"));
  ASSERT_EQ(replay_code, 0) << replay_out;
  EXPECT_EQ(read(path("replayed/estimate.csv")), read(path("live/estimate.csv")));

  // The bag, read by a reader that shares no code with its writer, field by field.
  const auto [expected_code, expected_out] =
      python({kTools + "ros2_expected_from_recording.py", path("rec/estimate.csv"), path("poses.csv"),
              path("odometry.csv")});
  ASSERT_EQ(expected_code, 0) << expected_out;
  const auto [check_code, check_out] =
      python({kTools + "check_rosbag2.py", path("rec/rosbag2"), "--expect-poses", path("poses.csv"),
              "--expect-odometry", path("odometry.csv"), "--twists-from-wheels", path("rec/odometry.csv")});
  EXPECT_EQ(check_code, 0) << check_out;
  const std::size_t poses = lines(read(path("rec/estimate.csv"))) - 1;
  EXPECT_GT(poses, 700u);
  EXPECT_NE(check_out.find("/beacon_pose (geometry_msgs/msg/PoseWithCovarianceStamped): " +
                           std::to_string(poses) + " messages"),
            std::string::npos)
      << check_out;
  EXPECT_NE(check_out.find("/tf_static (tf2_msgs/msg/TFMessage): 1 messages"), std::string::npos)
      << check_out;
}

TEST_F(Recording, ARecorderKilledMidRunLeavesARecordingValidToItsLastRow) {
  ChildProcess recorder(beaconloc("record", {"--out", path("rec"), "--receivers", kReceivers}),
                        path("record.log"));
  ChildProcess live(beaconloc("run", {"--duration-s", "20", "--speed", "1", "--bridge", "--wait-for-readers",
                                      "1", "--out", path("live")}),
                    path("live.log"));
  ASSERT_TRUE(eventually([&] { return lines(read(path("rec/estimate.csv"))) > 300; }, 60s)) << live.log();
  recorder.signal(SIGKILL);  // no chance to close anything
  recorder.wait(10s);
  live.signal(SIGTERM);
  live.wait(60s);

  // Every file ends with a whole row, and holds the samples the run published up to the kill, none
  // missing: the run's own recording begins with the recorder's.
  for (const char* file : {"tof.csv", "odometry.csv", "estimate.csv"}) {
    const std::string text = read(path("rec/") + file);
    ASSERT_FALSE(text.empty()) << file;
    EXPECT_EQ(text.back(), '\n') << file << " ends inside a row";
  }
  const std::string live_odometry = read(path("live/odometry.csv")),
                    recorded = read(path("rec/odometry.csv"));
  EXPECT_EQ(live_odometry.compare(0, recorded.size(), recorded), 0)
      << "odometry rows lost or altered before the kill";
  const std::string live_tofs = first_columns(read(path("live/tof.csv")), 6),
                    recorded_tofs = read(path("rec/tof.csv"));
  EXPECT_EQ(live_tofs.compare(0, recorded_tofs.size(), recorded_tofs), 0)
      << "TOF rows lost or altered before the kill";
  const auto [replay_code, replay_out] = replay(path("rec"), path("replayed"));
  EXPECT_EQ(replay_code, 0) << replay_out;
  EXPECT_EQ(replay_out.find("malformed"), std::string::npos) << replay_out;
  // The bag: every message written before the kill is there and whole; its metadata lags at most.
  const auto [check_code, check_out] =
      python({kTools + "check_rosbag2.py", path("rec/rosbag2"), "--after-kill", "--min-messages", "300"});
  EXPECT_EQ(check_code, 0) << check_out;
}

}  // namespace
}  // namespace beaconloc::testing
