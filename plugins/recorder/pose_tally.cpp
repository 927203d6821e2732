#include "pose_tally.hpp"

namespace beaconloc {

std::vector<const PoseWriter*> RobotPoses::current_writers(std::chrono::steady_clock::time_point now) const {
  std::vector<const PoseWriter*> out;
  const bool alternating = last_alternation && now - *last_alternation <= kConcurrentWritersWithin;
  for (const auto& [id, w] : writers) {
    if (now - w.last_heard > kConcurrentWritersWithin) continue;
    if (alternating || (newest && id == newest->writer)) out.push_back(&w);
  }
  return out;
}

PoseTally::Added PoseTally::add(const RecordedPose& p) {
  const std::string& writer = p.writer;
  RobotPoses& r = robots_[p.row.robot_id];
  if (!publishable(p.row.estimate)) {
    ++r.non_finite;
    return Added::kNonFinite;
  }
  auto [entry, first_of_writer] = r.writers.try_emplace(writer);
  PoseWriter& w = entry->second;
  // (Two localizers of one robot publish at the same odometry stamps: one's pose is no
  // correction of the other's.)
  const bool correction = !first_of_writer && w.newest_stamp_ns == p.row.estimate.stamp_ns;
  // Back after another writer's pose, its own previous one recent: both serve the robot.
  if (!first_of_writer && r.newest && r.newest->writer != writer &&
      p.received - w.last_heard <= kConcurrentWritersWithin) {
    r.had_conflict = true;
    r.last_alternation = p.received;
  }
  w.estimator = p.row.estimator;
  w.newest_stamp_ns = p.row.estimate.stamp_ns;
  w.last_heard = p.received;
  // A writer not heard for long, that was never part of a conflict, is forgotten: the state
  // stays O(robots) over restarts of a robot's localizer.
  if (!r.had_conflict) {
    for (auto it = r.writers.begin(); it != r.writers.end();) {
      it =
          p.received - it->second.last_heard > kConcurrentWritersWithin ? r.writers.erase(it) : std::next(it);
    }
  }
  r.newest = p;
  newest_ = p;
  if (correction) return Added::kCorrection;
  ++w.poses;
  ++r.poses;
  ++poses_;
  return Added::kNew;
}

}  // namespace beaconloc
