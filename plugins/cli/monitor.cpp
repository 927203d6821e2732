#include "monitor.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <utility>

#include "beaconloc/dds/stop_signal.hpp"
#include "diagnostics_recorder.hpp"
#include "fleet_view.hpp"
#include "pipeline.hpp"
#include "pose_recorder.hpp"

namespace beaconloc::cli {
namespace {

using Clock = std::chrono::steady_clock;

std::string joined_estimators(const std::vector<const PoseWriter*>& writers) {
  std::string s;
  for (const auto* w : writers) s += (s.empty() ? "" : ", ") + w->estimator;
  return s;
}

// One robot's line: its newest pose, or how long it has had none.
void print_robot(const std::string& robot, const RobotPoses& r, std::uint64_t shown, Clock::time_point now) {
  if (!r.newest) {
    std::printf("%s: no finite pose, %llu non-finite refused\n", robot.c_str(),
                static_cast<unsigned long long>(r.non_finite));
    return;
  }
  const auto& p = r.newest->row;
  std::printf("%s %s: %llu poses (+%llu), ", robot.c_str(), p.estimator.c_str(),
              static_cast<unsigned long long>(r.poses), static_cast<unsigned long long>(r.poses - shown));
  if (r.poses > shown) {
    const Pose2& x = p.estimate.pose_map_base;
    std::printf("x %.3f m, y %.3f m, yaw %.1f deg, %s", x.x(), x.y(), x.z() * 180.0 / M_PI,
                to_string(p.estimate.status));
  } else {
    std::printf("no new pose for %.0f s",
                std::floor(std::chrono::duration<double>(now - r.newest->received).count()));
  }
  if (r.non_finite) std::printf(", %llu non-finite refused", static_cast<unsigned long long>(r.non_finite));
  const auto writers = r.current_writers(now);
  if (writers.size() > 1) {
    std::printf("; CONFLICT: poses from %zu localizers at once (%s)", writers.size(),
                joined_estimators(writers).c_str());
  }
  std::printf("\n");
}

// The participants by id, for the fleet view: each one's name and rejections over every reason.
std::map<std::string, FleetParticipant> fleet_participants(const std::map<std::string, ParticipantReport>& reports) {
  std::map<std::string, FleetParticipant> out;
  for (const auto& [name, report] : reports) {
    FleetParticipant p{name, 0};
    for (const msg::RejectionCount& r : report.last.rejected()) p.rejected += r.count();
    out[report.participant_id] = std::move(p);
  }
  return out;
}

}  // namespace

int run_monitor(const MonitorOptions& o) {
  const bool keep_every_pose = !o.truth_file.empty() || !o.out_file.empty();
  PoseRecorder recorder(
      o.dds, keep_every_pose ? PoseRecorder::Keep::kEveryPose : PoseRecorder::Keep::kNewestPerRobot);
  DiagnosticsRecorder diagnostics(o.dds);
  const auto start = Clock::now();
  std::map<std::string, std::uint64_t> shown;                         // poses counted per robot
  std::map<std::string, std::pair<Liveness, int>> participant_shown;  // liveness, status
  FleetView fleet;
  while (!dds::wait_for_stop(std::chrono::seconds(1))) {
    const auto now = Clock::now();
    const auto robots = recorder.robots();
    if (robots.empty()) {
      std::printf("monitor: no pose received (%.0f s)\n",
                  std::floor(std::chrono::duration<double>(now - start).count()));
    }
    const auto reports = diagnostics.reports();
    if (o.fleet) {
      if (!robots.empty()) std::cout << format_fleet(fleet.update(robots, fleet_participants(reports), now));
    } else {
      for (const auto& [robot, r] : robots) {
        print_robot(robot, r, shown[robot], now);
        shown[robot] = r.poses;
      }
    }
    // A participant's line when it appears, and whenever its liveness or status changes.
    for (const auto& [name, report] : reports) {
      const std::pair<Liveness, int> state{report.liveness, static_cast<int>(report.last.status())};
      auto [it, first] = participant_shown.try_emplace(name, state);
      if (first || it->second != state) {
        print_report(name, report, std::cout);
        it->second = state;
      }
    }
    std::cout << std::flush;
    std::fflush(stdout);
    if (o.duration_s > 0.0 && now - start > std::chrono::duration<double>(o.duration_s)) break;
  }

  print_diagnostics(diagnostics.reports(), std::cout);
  const auto robots = recorder.robots();
  std::uint64_t poses = 0, non_finite = 0;
  for (const auto& [robot, r] : robots) {
    poses += r.poses;
    non_finite += r.non_finite;
    if (!r.had_conflict) continue;
    std::cout << "conflict: " << robot << " got poses from " << r.writers.size() << " localizers at once:";
    for (const auto& [id, w] : r.writers) std::cout << ' ' << w.estimator << " (" << w.poses << " poses)";
    std::cout << '\n';
  }
  if (poses == 0) {
    std::cout << "monitor: no pose received";
  } else {
    std::cout << "monitor: " << poses << " poses of " << robots.size() << " robot(s)";
  }
  if (non_finite) std::cout << ", " << non_finite << " non-finite poses refused";
  std::cout << '\n';
  std::cout << std::flush;
  const auto recorded = keep_every_pose ? recorder.poses() : std::vector<RecordedPose>{};
  if (!o.out_file.empty()) write_estimates_csv(o.out_file, rows_of(recorded));
  if (o.truth_file.empty()) return 0;
  if (recorded.empty()) {
    std::cout << "monitor: nothing to score against " << o.truth_file << '\n';
    return 1;
  }
  const PoseRunSummary s = summarize(recorded, load_truth_csv(o.truth_file));
  std::printf("poses: %zu at %.1f Hz; %s\n", s.poses, s.pose_rate_hz, format_metrics(s.metrics).c_str());
  return s.metrics.samples ? 0 : 1;  // poses, but none at a stamp the truth covers: nothing scored
}

}  // namespace beaconloc::cli
