#include "fleet_view.hpp"

#include <cstdio>

#include "beaconloc/core/participant_id.hpp"

namespace beaconloc::cli {

std::vector<FleetRow> FleetView::update(const std::map<std::string, RobotPoses>& robots,
                                        const std::map<std::string, FleetParticipant>& participants,
                                        std::chrono::steady_clock::time_point now) {
  const double elapsed_s = previous_ ? std::chrono::duration<double>(now - *previous_).count() : 0.0;
  std::map<std::string, std::uint64_t> gateway_rejected;  // by robot: its gateway's name says which
  const std::string gateway_prefix = "beaconloc.gateway.";
  for (const auto& [id, p] : participants) {
    if (p.name.compare(0, gateway_prefix.size(), gateway_prefix) == 0) {
      gateway_rejected[p.name.substr(gateway_prefix.size())] = p.rejected;
    }
  }
  std::vector<FleetRow> rows;
  for (const auto& [robot, r] : robots) {
    FleetRow row;
    row.robot = robot;
    const auto seen = poses_seen_.find(robot);
    if (elapsed_s > 0.0 && seen != poses_seen_.end() && r.poses >= seen->second) {
      row.pose_rate_hz = static_cast<double>(r.poses - seen->second) / elapsed_s;
    }
    poses_seen_[robot] = r.poses;
    if (r.newest) {
      row.status = r.newest->row.estimate.status;
      row.age_s = std::chrono::duration<double>(now - r.newest->received).count();
      row.stale = now - r.newest->received > kFleetStaleAfter;
      const auto p = participants.find(participant_of_writer(r.newest->writer));
      row.served_by = p != participants.end() ? p->second.name : participant_of_writer(r.newest->writer);
    }
    if (const auto g = gateway_rejected.find(robot); g != gateway_rejected.end())
      row.gateway_rejected = g->second;
    rows.push_back(std::move(row));
  }
  previous_ = now;
  return rows;
}

std::string format_fleet(const std::vector<FleetRow>& rows) {
  std::map<std::string, std::size_t> by_status, by_server;
  std::size_t stale = 0;
  for (const FleetRow& r : rows) {
    ++by_status[r.status ? to_string(*r.status) : "no pose"];
    if (r.stale) ++stale;
    if (!r.served_by.empty() && !r.stale) ++by_server[r.served_by];
  }
  std::string out = "fleet: " + std::to_string(rows.size()) + " robot(s)";
  const char* sep = ": ";
  for (const auto& [status, n] : by_status) {
    out += sep + std::to_string(n) + " " + status;
    sep = ", ";
  }
  out += "; " + std::to_string(stale) + " stale; served by:";
  if (by_server.empty()) out += " none";
  sep = " ";
  for (const auto& [server, n] : by_server) {
    out += sep + server + " " + std::to_string(n);
    sep = ", ";
  }
  out += "\n";
  char line[512];
  std::snprintf(line, sizeof line, "  %-16s %-13s %7s %7s %9s  %s\n", "robot", "status", "pose/s", "age s",
                "rejected", "served by");
  out += line;
  for (const FleetRow& r : rows) {
    const std::string status =
        r.status ? std::string(to_string(*r.status)) + (r.stale ? " stale" : "") : "no pose";
    const std::string rejected = r.gateway_rejected ? std::to_string(*r.gateway_rejected) : "-";
    std::snprintf(line, sizeof line, "  %-16s %-13s %7.1f %7.2f %9s  %s\n", r.robot.c_str(), status.c_str(),
                  r.pose_rate_hz, r.age_s, rejected.c_str(), r.served_by.empty() ? "-" : r.served_by.c_str());
    out += line;
  }
  return out;
}

}  // namespace beaconloc::cli
