#include "fleet_feeder.hpp"

#include <beaconlocPubSubTypes.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/topics.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "offline_run.hpp"
#include "sim/scenario.hpp"

namespace beaconloc::bench {

std::string robot_name(int i) { return "robot-" + std::to_string(i); }

// --role feeder: every robot's samples on the wall clock for `seconds`. Robots are not in step,
// as separate gateways are not: each writes its 10 ms of samples at its own phase (0-9 ms) into
// each step, its stamps shifted by as much.
// Robots take their events from one of a few simulated runs (different seeds), so the feeder's
// own cost is the writes, not the simulation.
int run_feeder(const dds::DdsOptions& dds, int robots, double seconds) {
  const sim::Scenario scenario = sim::default_scenario();
  constexpr int kRuns = 4;
  constexpr int kPhases = 10;  // 1 ms apart within the 10 ms odometry period
  std::vector<std::vector<SourceEvent>> runs;
  for (int s = 0; s < kRuns; ++s)
    runs.push_back(simulate(scenario, static_cast<std::uint64_t>(s + 1), seconds + 1.0));

  dds::Participant participant(dds, "beaconloc.bench.fleet_feeder");
  auto map_writer = participant.writer<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic);
  // The gateways' writer QoS with a history sized for a writer of many robots
  // (fleet_feeder_qos.xml says why).
  auto tof_writer = participant.writer<msg::RawTofPubSubType>(
      {dds::kRawTofTopic.name, "fleet_feeder.raw_tof.writer", dds::kRawTofTopic.reader_profile});
  auto odometry_writer = participant.writer<msg::OdometryPubSubType>(
      {dds::kOdometryTopic.name, "fleet_feeder.odometry.writer", dds::kOdometryTopic.reader_profile});
  auto map = dds::to_msg(BeaconMap(scenario.beacon_list()), "map");
  map_writer->write(&map);
  if (!dds::wait_for_matched_readers({tof_writer, odometry_writer}, std::chrono::seconds(10))) {
    std::fprintf(stderr, "feeder: no reader matched\n");
    return 1;
  }
  struct Robot {
    std::string name;
    std::uint64_t sequence = 0;
  };
  std::vector<Robot> fleet;
  for (int i = 0; i < robots; ++i) fleet.push_back({robot_name(i)});
  // next[run][phase]: the first event of the run not yet written by the robots of that phase.
  std::vector<std::vector<std::size_t>> next(kRuns, std::vector<std::size_t>(kPhases, 0));
  std::uint64_t written = 0, failed = 0;
  const StampNs offset_ns = dds::wall_clock_ns();
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = start + std::chrono::nanoseconds(s_to_ns(seconds));
  std::chrono::steady_clock::duration max_late{0};
  for (StampNs wall_ns = kNsPerMillisecond; wall_ns <= s_to_ns(seconds); wall_ns += kNsPerMillisecond) {
    std::this_thread::sleep_until(start + std::chrono::nanoseconds(wall_ns));
    // A feeder behind the wall clock (more robots than the machine writes for) stops on time
    // anyway, with what it could not write untold: its lateness says how far behind it was.
    const auto now = std::chrono::steady_clock::now();
    max_late = std::max(max_late, now - (start + std::chrono::nanoseconds(wall_ns)));
    if (now > deadline) break;
    const auto phase = static_cast<int>((wall_ns / kNsPerMillisecond) % kPhases);
    const StampNs shift_ns = phase * kNsPerMillisecond;
    const StampNs sim_ns = wall_ns - shift_ns;  // a multiple of 10 ms
    for (int s = 0; s < kRuns; ++s) {
      const auto& events = runs[static_cast<std::size_t>(s)];
      std::size_t& first = next[static_cast<std::size_t>(s)][static_cast<std::size_t>(phase)];
      std::size_t end = first;
      while (end < events.size() && events[end].stamp_ns <= sim_ns) ++end;
      for (int i = phase * kRuns + s; i < robots; i += kRuns * kPhases) {
        Robot& robot = fleet[static_cast<std::size_t>(i)];
        for (std::size_t k = first; k < end; ++k) {
          SourceEvent e = events[k];
          bool ok = true;
          if (e.kind == SourceEvent::Kind::kOdometry) {
            e.odometry.stamp_ns += offset_ns + shift_ns;
            auto m = dds::to_msg(robot.name, e.odometry, robot.sequence++);
            ok = odometry_writer->write(&m);
          } else if (e.kind == SourceEvent::Kind::kTof) {
            e.tof.fire_stamp_ns += offset_ns + shift_ns;
            auto m = dds::to_msg(robot.name, e.tof);
            ok = tof_writer->write(&m);
          } else {
            continue;
          }
          ok ? ++written : ++failed;
        }
      }
      first = end;
    }
  }
  std::printf("feeder written=%llu failed=%llu late_ms=%.3f\n", static_cast<unsigned long long>(written),
              static_cast<unsigned long long>(failed),
              std::chrono::duration<double, std::milli>(max_late).count());
  return failed == 0 ? 0 : 1;
}

}  // namespace beaconloc::bench
