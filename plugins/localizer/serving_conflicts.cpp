#include "serving_conflicts.hpp"

#include <iterator>

namespace beaconloc {

void ServingConflicts::set_own_robots(const std::vector<std::string>& robots, StampNs now_ns) {
  own_ = {robots.begin(), robots.end()};
  find_conflicts(now_ns);
}

void ServingConflicts::on_peer_report(const std::string& peer, const std::string& name,
                                      const std::vector<std::string>& robots, StampNs now_ns) {
  if (robots.empty()) {
    peers_.erase(peer);  // serves no robot: no conflict, nothing to keep
  } else {
    peers_[peer] = Peer{name, {robots.begin(), robots.end()}, now_ns};
  }
  find_conflicts(now_ns);
}

void ServingConflicts::on_peer_gone(const std::string& peer, StampNs now_ns) {
  peers_.erase(peer);
  find_conflicts(now_ns);
}

void ServingConflicts::on_peers_gone(const std::string& prefix, StampNs now_ns) {
  for (auto it = peers_.begin(); it != peers_.end();) {
    it = it->first.compare(0, prefix.size(), prefix) == 0 ? peers_.erase(it) : std::next(it);
  }
  find_conflicts(now_ns);
}

void ServingConflicts::refresh(StampNs now_ns) { find_conflicts(now_ns); }

void ServingConflicts::find_conflicts(StampNs now_ns) {
  for (auto it = peers_.begin(); it != peers_.end();) {
    it = now_ns - it->second.heard_ns > silent_after_ns_ ? peers_.erase(it) : std::next(it);
  }
  std::map<std::string, std::set<std::string>> found;
  for (const auto& [id, peer] : peers_) {
    for (const auto& robot : peer.robots) {
      if (!own_.count(robot)) continue;
      found[robot].insert(id);
      const auto before = conflicts_.find(robot);
      if (before == conflicts_.end() || !before->second.count(id)) ++found_;
    }
  }
  conflicts_ = std::move(found);
}

PoseStatus ServingConflicts::status_of(const std::string& robot, PoseStatus status) const {
  return status == PoseStatus::kOk && contested(robot) ? PoseStatus::kDegraded : status;
}

std::string ServingConflicts::describe(std::size_t max_robots) const {
  std::string s;
  std::size_t listed = 0;
  for (const auto& [robot, ids] : conflicts_) {
    if (listed++ == max_robots) {
      s += "; and " + std::to_string(conflicts_.size() - max_robots) + " more robot(s)";
      break;
    }
    s += (s.empty() ? "robot " : "; robot ") + robot + " also served by ";
    bool first = true;
    for (const auto& id : ids) {
      s += (first ? "" : ", ") + peers_.at(id).name;
      first = false;
    }
  }
  return s;
}

}  // namespace beaconloc
