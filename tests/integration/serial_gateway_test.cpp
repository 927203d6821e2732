// The serial gateway on a pseudo-terminal line (socat's linked pair, as a USB receiver module
// appears): `beaconloc serial-sim` writes what a module sends on one end, `beaconloc gateway
// --serial` reads the other, a decoder and a localizer localize from it. Garbage, split and
// corrupted frames, a stalled line and an unplugged device, each with what it must do to the
// counts and to the poses; and Marvelmind's raw distances.
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <regex>

#include "beaconloc/dds/topics.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "participants_test.hpp"
#include "pose_recorder.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

// The built-in scenario's robot (examples/scenarios/default.yaml): three receivers on a 0.19 m
// circle (their coordinates as the simulator computes them), starting at (0.5, 0, 0); the gateway
// and localizer are told as on a real robot.
const std::string kReceivers =
    "0.19:0,-0.09499999999999996:0.16454482671904336,-0.09500000000000008:-0.1645448267190433";

class SerialLine : public ParticipantsTest {
 protected:
  void SetUp() override {
    ParticipantsTest::SetUp();
    std::ofstream beacons(path("beacons.csv"));
    beacons << "beacon_id,x_m,y_m,z_m\n1,0,-0.3,2.011\n2,1.5,-0.3,2.011\n3,3,-0.3,2.011\n"
               "4,0,1.5,2.011\n5,1.5,1.5,2.011\n6,3,1.5,2.011\n";
    open_line();
  }
  // socat's pair of pseudo-terminals, linked as gw (the gateway's end) and sim (the module's).
  void open_line() {
    line_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{BEACONLOC_SOCAT, "pty,raw,echo=0,link=" + path("gw"),
                                 "pty,raw,echo=0,link=" + path("sim")},
        path("socat.log"));
    ASSERT_TRUE(eventually(
        [&] { return std::filesystem::exists(path("gw")) && std::filesystem::exists(path("sim")); }, 10s))
        << line_->log();
  }
  void unplug() {
    line_->signal(SIGTERM);
    line_->wait(10s);
    line_.reset();
  }
  std::vector<std::string> gateway_command(std::vector<std::string> extra = {}) const {
    std::vector<std::string> args{"--serial", path("gw"), "--beacons", path("beacons.csv")};
    args.insert(args.end(), extra.begin(), extra.end());
    return command("gateway", args);
  }
  std::vector<std::string> sim_command(std::vector<std::string> extra) const {
    std::vector<std::string> args{BEACONLOC_EXECUTABLE, "serial-sim", "--device", path("sim")};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  // The decoder and localizer of the built-in scenario's robot.
  void start_pipeline() {
    decoder_ = std::make_unique<ChildProcess>(
        command("decoder", {"--max-range-m", "5", "--range-sigma-m", "0.01"}), path("decoder.log"));
    localizer_ = std::make_unique<ChildProcess>(
        command("localizer", {"--receivers", kReceivers, "--initial-pose", "0.5", "0", "0"}),
        path("localizer.log"));
  }
  static std::uint64_t sim_count(const std::string& log, const std::string& what) {
    std::smatch m;
    if (!std::regex_search(log, m, std::regex("([0-9]+) " + what))) return 0;
    return std::stoull(m[1]);
  }
  std::unique_ptr<ChildProcess> line_, decoder_, localizer_;
};

// Counts the robot's RawTof and Odometry samples on the bus (the gateway's output).
class BusCounter {
 public:
  explicit BusCounter(const dds::DdsOptions& dds) : participant_(dds, "test.bus_counter") {
    tofs_reader_ = participant_.subscribe<msg::RawTofPubSubType>(dds::kRawTofTopic,
                                                                 [this](const msg::RawTof&) { ++tofs; });
    odometry_reader_ = participant_.subscribe<msg::OdometryPubSubType>(
        dds::kOdometryTopic, [this](const msg::Odometry&) { ++odometry; });
  }
  std::atomic<std::uint64_t> tofs{0}, odometry{0};

 private:
  dds::Participant participant_;
  dds::Reader tofs_reader_, odometry_reader_;
};

TEST_F(SerialLine, AGatewayOnASerialLineLocalizesAndLosesNothingToGarbageSplitOrCorruptFrames) {
  DiagnosticsRecorder diagnostics(dds_);
  PoseRecorder poses(dds_);
  BusCounter bus(dds_);
  start_pipeline();
  ChildProcess gateway(gateway_command(), path("gateway.log"));
  ASSERT_TRUE(wait_until_reporting(diagnostics, {"beaconloc.gateway.robot1", kDecoder, kRangeEkfLocalizer}))
      << gateway.log() << decoder_->log() << localizer_->log();
  const auto [code, sim_log] =
      run_command(sim_command({"--duration-s", "12", "--garbage-every-s", "0.5", "--corrupt-every-s", "0.5",
                               "--split-frames", "--truth-out", path("truth.csv")}),
                  60s);
  ASSERT_EQ(code, 0) << sim_log;
  const std::uint64_t intact = sim_count(sim_log, "samples intact"),
                      corrupted = sim_count(sim_log, "corrupted");
  ASSERT_GT(sim_count(sim_log, "garbage runs"), 5u) << sim_log;
  ASSERT_GT(corrupted, 5u) << sim_log;
  // Every intact frame reached the bus: garbage and splits cost no sample, a corrupted frame only itself.
  EXPECT_TRUE(eventually([&] { return bus.tofs + bus.odometry == intact; }, 10s))
      << bus.tofs << " TOFs + " << bus.odometry << " odometry on the bus, " << intact
      << " intact frames sent\n"
      << sim_log;
  const auto report =
      wait_for_diagnostics(diagnostics, "beaconloc.gateway.robot1", [&](const msg::Diagnostics& d) {
        return rejected_count(d, "source.serial.garbage") > 0 &&
               rejected_count(d, "source.serial.bad_checksum") > 0;
      });
  EXPECT_GT(rejected_count(report, "source.serial.garbage"), 0u);
  EXPECT_GT(rejected_count(report, "source.serial.bad_checksum"), 0u);
  std::uint64_t refused_frames = 0;
  for (const char* reason :
       {"bad_checksum", "bad_length", "unknown_type", "unknown_version", "reserved_bits_set"}) {
    refused_frames += rejected_count(report, std::string("source.serial.") + reason);
  }
  EXPECT_LE(refused_frames, corrupted) << "a frame refused that was sent intact";

  // Localized against the truth on the host's clock, as the gateway stamps the frames.
  const TruthTrack truth = load_truth_csv(path("truth.csv"));
  ASSERT_TRUE(
      wait_for_pose(poses, "robot1", last_truth_stamp_ns(path("truth.csv")) - 200 * kNsPerMillisecond));
  const PoseRunSummary summary = summarize(poses.poses(), truth);
  EXPECT_GT(summary.metrics.samples, 800u);
  EXPECT_LT(summary.metrics.position_rms_m, 0.05) << "the serial line's stamps or samples are off";
  stop_cleanly(gateway, "gateway");
  stop_cleanly(*localizer_, "localizer");
  stop_cleanly(*decoder_, "decoder");
}

TEST_F(SerialLine, AStalledLineIsCountedAndMissesTheBusDeadlinesAndTheRobotIsLocalizedAfter) {
  DiagnosticsRecorder diagnostics(dds_);
  PoseRecorder poses(dds_);
  start_pipeline();
  ChildProcess gateway(gateway_command(), path("gateway.log"));
  ASSERT_TRUE(wait_until_reporting(diagnostics, {"beaconloc.gateway.robot1", kDecoder, kRangeEkfLocalizer}))
      << gateway.log() << decoder_->log() << localizer_->log();
  // The line goes silent 4 s in, for 3 s, and speaks again until 12 s: every check below is made
  // while the module still runs (its end would be a silence of its own).
  ChildProcess sim(sim_command({"--duration-s", "12", "--stall-at-s", "4", "--stall-s", "3", "--truth-out",
                                path("truth.csv")}),
                   path("sim.log"));
  ASSERT_TRUE(wait_for_pose_span(poses, "robot1", 1s)) << gateway.log();
  const auto before =
      wait_for_diagnostics(diagnostics, kRangeEkfLocalizer, [](const msg::Diagnostics&) { return true; });
  EXPECT_EQ(rejected_count(diagnostics.latest().at("beaconloc.gateway.robot1"), "source.serial.stalled"), 0u);
  const auto stalled = wait_for_diagnostics(
      diagnostics, "beaconloc.gateway.robot1",
      [](const msg::Diagnostics& d) { return rejected_count(d, "source.serial.stalled") > 0; });
  EXPECT_EQ(rejected_count(stalled, "source.serial.stalled"), 1u);
  const auto missed = wait_for_diagnostics(diagnostics, kRangeEkfLocalizer, [&](const msg::Diagnostics& d) {
    return d.deadline_misses() > before.deadline_misses();
  });
  EXPECT_GT(missed.deadline_misses(), before.deadline_misses())
      << "the stalled line's odometry missed no deadline";
  // Localized again after the stall, the module still running: a pose stamped after the line
  // spoke again (7 s in), and still one stall counted.
  const StampNs spoke_again_ns = dds::wall_clock_ns() + 3 * kNsPerSecond;
  EXPECT_TRUE(wait_for_pose(poses, "robot1", spoke_again_ns)) << sim.log();
  const auto sim_code = sim.wait(30s);
  ASSERT_TRUE(sim_code);
  EXPECT_EQ(*sim_code, 0) << sim.log();
  stop_cleanly(gateway, "gateway");
  stop_cleanly(*localizer_, "localizer");
  stop_cleanly(*decoder_, "decoder");
}

TEST_F(SerialLine, AnUnpluggedDeviceIsReopenedWhenItComesBack) {
  DiagnosticsRecorder diagnostics(dds_);
  PoseRecorder poses(dds_);
  start_pipeline();
  ChildProcess gateway(gateway_command(), path("gateway.log"));
  ASSERT_TRUE(wait_until_reporting(diagnostics, {"beaconloc.gateway.robot1", kDecoder, kRangeEkfLocalizer}))
      << gateway.log() << decoder_->log() << localizer_->log();
  ChildProcess sim(sim_command({"--duration-s", "30", "--truth-out", path("truth.csv")}), path("sim.log"));
  ASSERT_TRUE(wait_for_pose_span(poses, "robot1", 2s)) << gateway.log();
  unplug();
  const auto gone = wait_for_diagnostics(
      diagnostics, "beaconloc.gateway.robot1",
      [](const msg::Diagnostics& d) { return rejected_count(d, "source.serial.device_gone") > 0; });
  ASSERT_EQ(rejected_count(gone, "source.serial.device_gone"), 1u) << gateway.log();
  const StampNs replugged_ns = dds::wall_clock_ns();
  ASSERT_NO_FATAL_FAILURE(open_line());
  const auto back = wait_for_diagnostics(
      diagnostics, "beaconloc.gateway.robot1",
      [](const msg::Diagnostics& d) { return rejected_count(d, "source.serial.reopened") > 0; });
  EXPECT_EQ(rejected_count(back, "source.serial.reopened"), 1u) << gateway.log();
  // The module's new line is read: poses stamped after the device came back.
  EXPECT_TRUE(wait_for_pose(poses, "robot1", replugged_ns + kNsPerSecond)) << sim.log();
  sim.signal(SIGTERM);
  sim.wait(10s);
  stop_cleanly(gateway, "gateway");
  stop_cleanly(*localizer_, "localizer");
  stop_cleanly(*decoder_, "decoder");
}

// Marvelmind's raw distances (docs/serial-protocol.md): each distance becomes a TOF the decoder
// turns back into the distance, to the millimetre the protocol carries.
TEST_F(SerialLine, MarvelmindRawDistancesBecomeRangesInWholeMillimetres) {
  DiagnosticsRecorder diagnostics(dds_);
  std::mutex mutex;
  std::vector<msg::BeaconRange> ranges;
  dds::Participant reader_participant(dds_, "test.ranges");
  dds::Reader reader = reader_participant.subscribe<msg::BeaconRangePubSubType>(
      dds::kBeaconRangeTopic, [&](const msg::BeaconRange& r) {
        std::lock_guard<std::mutex> lock(mutex);
        ranges.push_back(r);
      });
  decoder_ = std::make_unique<ChildProcess>(command("decoder", {"--max-range-m", "5"}), path("decoder.log"));
  ChildProcess gateway(gateway_command({"--serial-protocol", "marvelmind"}), path("gateway.log"));
  ASSERT_TRUE(wait_until_reporting(diagnostics, {"beaconloc.gateway.robot1", kDecoder}));
  const auto [code, sim_log] =
      run_command(sim_command({"--duration-s", "4", "--serial-protocol", "marvelmind"}), 60s);
  ASSERT_EQ(code, 0) << sim_log;
  const std::uint64_t sent = sim_count(sim_log, "samples intact");
  ASSERT_GT(sent, 5u) << sim_log;
  EXPECT_TRUE(eventually(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return ranges.size() == sent;
      },
      10s))
      << ranges.size() << " ranges of " << sent << " distances sent";
  std::lock_guard<std::mutex> lock(mutex);
  for (const auto& r : ranges) {
    EXPECT_GE(r.beacon_id(), 1u);
    EXPECT_LE(r.beacon_id(), 6u);
    EXPECT_NEAR(r.range_m() * 1e3, std::round(r.range_m() * 1e3), 1e-6) << "not the millimetres sent";
  }
  const auto report = diagnostics.latest().at("beaconloc.gateway.robot1");
  EXPECT_EQ(rejected_count(report, "source.serial.garbage"), 0u);
  stop_cleanly(gateway, "gateway");
  stop_cleanly(*decoder_, "decoder");
}

}  // namespace
}  // namespace beaconloc::testing
