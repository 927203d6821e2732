// The beacon map on the bus as a user changes it (issue 23, item 1): a gateway replaced by one
// whose scenario has fewer beacons, two gateways with different maps at once, and maps that no
// site has (a repeated id, a NaN position). The localizer crashed on the first two; every one
// must leave it running, say what happened, and localize on the map it keeps.
#include <beaconlocPubSubTypes.h>
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "beaconloc/core/pose_error.hpp"
#include "beaconloc/dds/convert.hpp"
#include "diagnostics_recorder.hpp"
#include "participants_test.hpp"
#include "pose_recorder.hpp"
#include "process.hpp"
#include "sim/scenario.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

const std::string kSource = BEACONLOC_SOURCE_DIR;

class BeaconMapOnTheBus : public ParticipantsTest {
 protected:
  // The default scenario with some beacon lines taken out or changed: `edit` maps each line.
  std::string scenario_file(const std::string& name,
                            const std::function<std::string(const std::string&)>& edit) {
    std::ifstream in(kSource + "/examples/scenarios/default.yaml");
    std::ofstream out(path(name));
    for (std::string line; std::getline(in, line);) out << edit(line) << '\n';
    return path(name);
  }
  // The ok poses of `robot` stamped after from_ns (the gateways stamp with the wall clock).
  static std::vector<RecordedPose> ok_poses_after(const PoseRecorder& poses, const std::string& robot,
                                                  StampNs from_ns) {
    std::vector<RecordedPose> out;
    for (const auto& p : poses.poses()) {
      if (p.row.robot_id == robot && p.row.estimate.stamp_ns > from_ns &&
          p.row.estimate.status == PoseStatus::kOk)
        out.push_back(p);
    }
    return out;
  }
  // Position error of poses against a gateway's truth file (each pose is at one of its stamps).
  static PoseErrorAccumulator error_against(const std::vector<RecordedPose>& poses,
                                            const std::string& truth_csv) {
    const TruthTrack truth = load_truth_csv(truth_csv);
    PoseErrorAccumulator error;
    for (const auto& p : poses) {
      if (const auto t = truth.at(p.row.estimate.stamp_ns, 0))
        error.add(t->pose_map_base, p.row.estimate.pose_map_base);
    }
    return error;
  }
};

// Localized again: 2 s of ok poses (100 Hz) after the map changed.
constexpr std::size_t kRelocalized = 200;

const char* kLocalizer = "beaconloc.localizer.range_ekf";

// The user's sequence: stop the gateway, start one on a scenario without beacons 4-6 (the three
// left are on one line), and later one with every beacon again. The localizer restarts the
// robot on each new map, says so, and keeps publishing; it crashed within 3 s before.
TEST_F(BeaconMapOnTheBus, AGatewayWithFewerBeaconsReplacesTheMapAndTheLocalizerGoesOn) {
  DiagnosticsRecorder diagnostics(dds_);
  PoseRecorder poses(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  auto gateway = std::make_unique<ChildProcess>(command("gateway", {"--seed", "3"}), path("gateway1.log"));
  ASSERT_TRUE(eventually([&] { return poses.count() > 100; }, 20s)) << localizer.log();
  gateway->signal(SIGTERM);
  ASSERT_TRUE(gateway->wait(15s));

  const std::string fewer = scenario_file("fewer.yaml", [](const std::string& line) {
    for (const char* id : {"{id: 4,", "{id: 5,", "{id: 6,"}) {
      if (line.find(id) != std::string::npos) return std::string();
    }
    // The firing order may name only beacons that are there.
    if (line.find("firing_order:") != std::string::npos) return std::string("  firing_order: [1, 2, 3]");
    return line;
  });
  gateway = std::make_unique<ChildProcess>(
      command("gateway", {"--scenario", fewer, "--seed", "4", "--truth-out", path("fewer.csv")}),
      path("gateway2.log"));
  const auto replaced = wait_for_diagnostics(diagnostics, kLocalizer, [](const msg::Diagnostics& d) {
    return d.message().find("beacon map replaced 1 time(s)") != std::string::npos;
  });
  ASSERT_NE(replaced.message().find("beacon map replaced 1 time(s)"), std::string::npos)
      << replaced.message() << "\n"
      << localizer.log();
  // The localizer goes on and localizes the robot again on the new map: ok poses of the new
  // gateway's run (the old gateway had stopped before the report), right against its truth.
  EXPECT_TRUE(eventually(
      [&] { return ok_poses_after(poses, "robot1", replaced.stamp_ns()).size() >= kRelocalized; }, 30s))
      << "not localized again on the new map\n"
      << localizer.log();
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(*gateway, "gateway on fewer beacons"));
  const auto on_fewer =
      error_against(ok_poses_after(poses, "robot1", replaced.stamp_ns()), path("fewer.csv"));
  std::printf("on beacons 1-3: %zu ok poses, position RMS %.3f m, max %.3f m\n", on_fewer.samples(),
              on_fewer.position_rms_m(), on_fewer.position_max_m());
  EXPECT_GE(on_fewer.samples(), kRelocalized);
  EXPECT_LE(on_fewer.position_rms_m(), 0.1);

  // Every beacon again, two gateways at once (one moved by 0.5 m): two maps on the bus.
  const std::string moved = scenario_file("moved.yaml", [](const std::string& line) {
    const std::string from = "{id: 1, position_m: [0.0,";
    return line.find(from) == std::string::npos ? line : "  - {id: 1, position_m: [0.5, -0.3, 2.011]}";
  });
  ChildProcess a(command("gateway", {"--seed", "5", "--robot", "robot1", "--truth-out", path("site.csv")}),
                 path("gateway3.log"));
  ChildProcess b(command("gateway", {"--scenario", moved, "--seed", "6", "--robot", "robot2"}),
                 path("gateway4.log"));
  // Two live gateways whose maps disagree: one of them is wrong, so the localizer says so and no
  // pose of either robot is ok (each is computed on whichever map came last).
  auto disagree = [](const msg::Diagnostics& d) {
    return d.message().find("beacon maps disagree: 2 writers publish 2 different beacon maps") != std::string::npos;
  };
  const auto conflict = wait_for_diagnostics(diagnostics, kLocalizer, disagree);
  ASSERT_TRUE(disagree(conflict)) << conflict.message() << "\n" << localizer.log();
  EXPECT_EQ(conflict.status(), msg::PARTICIPANT_STATUS_DEGRADED);
  auto poses_after = [&](const std::string& robot, StampNs from_ns) {
    std::vector<RecordedPose> out;
    for (const auto& p : poses.poses()) {
      if (p.row.robot_id == robot && p.row.estimate.stamp_ns > from_ns) out.push_back(p);
    }
    return out;
  };
  for (const char* robot : {"robot1", "robot2"}) {
    // Poses made after the report (the gateways stamp with the wall clock, as the report is).
    ASSERT_TRUE(eventually([&] { return poses_after(robot, conflict.stamp_ns()).size() >= 100; }, 30s))
        << robot << "\n" << localizer.log();
    for (const auto& p : poses_after(robot, conflict.stamp_ns())) {
      ASSERT_NE(p.row.estimate.status, PoseStatus::kOk) << robot << " at " << p.row.estimate.stamp_ns;
    }
  }
  std::printf("two maps on the bus: %s\n", conflict.message().c_str());
  // The gateway with the moved beacon leaves: the map of the one left is the site's (whichever came
  // last before), and its robot is localized on it again, right against its truth.
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(b, "gateway with the moved beacon"));
  const auto agreed = wait_for_diagnostics(diagnostics, kLocalizer, [&](const msg::Diagnostics& d) {
    return d.stamp_ns() > conflict.stamp_ns() && !disagree(d);
  });
  ASSERT_FALSE(disagree(agreed)) << agreed.message();
  EXPECT_TRUE(eventually([&] { return ok_poses_after(poses, "robot1", agreed.stamp_ns()).size() >= kRelocalized; }, 30s))
      << "not localized again once the maps agree\n"
      << localizer.log();
  ASSERT_NO_FATAL_FAILURE(stop_cleanly(a, "gateway"));
  const auto on_site = error_against(ok_poses_after(poses, "robot1", agreed.stamp_ns()), path("site.csv"));
  std::printf("once the maps agree: %zu ok poses, position RMS %.3f m\n", on_site.samples(), on_site.position_rms_m());
  EXPECT_GE(on_site.samples(), kRelocalized);
  EXPECT_LE(on_site.position_rms_m(), 0.1);
  stop_cleanly(localizer, "localizer");
  stop_cleanly(decoder, "decoder");
  for (const auto& p : poses.poses()) ASSERT_TRUE(publishable(p.row.estimate));
}

// Maps no site has, written to the bus by a faulty gateway: each refused whole by reason in the
// localizer's and the decoder's Diagnostics; the good map they had stays in use.
TEST_F(BeaconMapOnTheBus, MalformedMapsAreRefusedByReasonAndTheGoodOneKept) {
  DiagnosticsRecorder diagnostics(dds_);
  ChildProcess localizer(command("localizer"), path("localizer.log"));
  ChildProcess decoder(command("decoder"), path("decoder.log"));
  dds::Participant bus(dds_, "test.faulty_gateway");
  auto map_writer = bus.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic);
  ASSERT_TRUE(eventually(
      [&] {
        eprosima::fastdds::dds::PublicationMatchedStatus status;
        map_writer->get_publication_matched_status(status);
        return status.current_count >= 2;
      },
      10s));
  msg::BeaconMap good = dds::to_msg(BeaconMap(sim::default_scenario().beacons), "map");
  map_writer->write(&good);
  for (const char* name : {kLocalizer, "beaconloc.decoder"}) {  // taken before the next replaces it
    const auto d = wait_for_diagnostics(diagnostics, name, [](const msg::Diagnostics& x) {
      return x.message().find("waiting for the beacon map") == std::string::npos;
    });
    ASSERT_EQ(d.message().find("waiting for the beacon map"), std::string::npos)
        << name << ": " << d.message();
  }
  std::vector<std::pair<msg::BeaconMap, const char*>> bad;
  bad.push_back({good, "beacon_map.duplicate_id"});
  bad.back().first.beacons().push_back(good.beacons()[1]);
  bad.push_back({good, "beacon_map.non_finite_position"});
  bad.back().first.beacons()[2].z_m(std::numeric_limits<double>::quiet_NaN());
  bad.push_back({good, "beacon_map.position_out_of_range"});
  bad.back().first.beacons()[0].x_m(1e300);
  bad.push_back({good, "beacon_map.empty"});
  bad.back().first.beacons().clear();
  // One at a time: the topic keeps the newest map only (keep_last 1), as a late joiner needs.
  for (auto& [map, reason] : bad) {
    map_writer->write(&map);
    for (const char* name : {kLocalizer, "beaconloc.decoder"}) {
      const auto d = wait_for_diagnostics(diagnostics, name, [reason = reason](const msg::Diagnostics& x) {
        return rejected_count(x, reason) > 0;
      });
      EXPECT_EQ(rejected_count(d, reason), 1u) << name;
      EXPECT_EQ(d.message().find("waiting for the beacon map"), std::string::npos)
          << name << ": " << d.message();
    }
  }
  stop_cleanly(localizer, "localizer");
  stop_cleanly(decoder, "decoder");
}

}  // namespace
}  // namespace beaconloc::testing
