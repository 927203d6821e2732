#pragma once
// `beaconloc monitor --fleet`: one row per robot with its pose status, pose rate, age, the
// rejections of its gateway and the localizer (shard) serving it, and a summary line; built
// from what the monitor records (PoseTally's robots, the participants' Diagnostics), DDS-free.
#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pose_tally.hpp"

namespace beaconloc::cli {

// A robot whose newest pose is older than this is stale: its localizer, gateway or link stopped
// (a localizer writes one pose per 10 ms odometry sample; a shard's takeover takes about 1 s).
inline constexpr std::chrono::milliseconds kFleetStaleAfter{2000};

// What the Diagnostics say of a participant.
struct FleetParticipant {
  std::string name;
  std::uint64_t rejected = 0;  // every reason's count
};

struct FleetRow {
  std::string robot;
  std::optional<PoseStatus> status;  // of its newest finite pose; none before one
  bool stale = false;                // newest pose older than kFleetStaleAfter
  double pose_rate_hz = 0.0;         // poses received since the previous view, per second
  double age_s = 0.0;                // since its newest pose arrived
  // Rejections of its gateway (the participant named beaconloc.gateway.<robot>), if it reports.
  std::optional<std::uint64_t> gateway_rejected;
  std::string served_by;  // the participant of its newest pose's writer, or its id when it never reported
};

class FleetView {
 public:
  // The rows at `now`, sorted by robot; rates over the time since the previous call (0 at the
  // first). participants: by participant id (dds::participant_of_writer of their writers).
  std::vector<FleetRow> update(const std::map<std::string, RobotPoses>& robots,
                               const std::map<std::string, FleetParticipant>& participants,
                               std::chrono::steady_clock::time_point now);

 private:
  std::map<std::string, std::uint64_t> poses_seen_;  // per robot, at the previous call
  std::optional<std::chrono::steady_clock::time_point> previous_;
};

// "fleet: 4 robot(s): 1 initializing, 3 ok; 0 stale; served by: NAME 2, NAME 2" (stale robots
// not counted as served), then the table.
std::string format_fleet(const std::vector<FleetRow>& rows);

}  // namespace beaconloc::cli
