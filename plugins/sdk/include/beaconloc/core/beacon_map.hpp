#pragma once
// The site's ceiling beacons at known positions in the map frame.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

namespace beaconloc {

struct Beacon {
  std::uint32_t id = 0;
  Eigen::Vector3d position_map_m = Eigen::Vector3d::Zero();
  std::uint32_t group = 0;
};

class BeaconMap {
 public:
  BeaconMap() = default;
  explicit BeaconMap(const std::vector<Beacon>& beacons) {
    for (const auto& b : beacons) beacons_[b.id] = b;
  }
  const Beacon* find(std::uint32_t id) const {
    auto it = beacons_.find(id);
    return it == beacons_.end() ? nullptr : &it->second;
  }
  bool empty() const { return beacons_.empty(); }
  std::size_t size() const { return beacons_.size(); }
  std::vector<Beacon> beacons() const {
    std::vector<Beacon> out;
    for (const auto& [id, b] : beacons_) out.push_back(b);
    return out;
  }

 private:
  std::map<std::uint32_t, Beacon> beacons_;  // ordered: deterministic iteration
};

}  // namespace beaconloc
