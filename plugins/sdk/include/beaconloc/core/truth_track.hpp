#pragma once
// Ground-truth poses by stamp, looked up at the stamps of estimates.
#include <map>
#include <optional>

#include "beaconloc/core/pose2.hpp"
#include "beaconloc/core/time.hpp"

namespace beaconloc {

class TruthTrack {
 public:
  void add(StampNs stamp_ns, const Pose2& pose) { poses_[stamp_ns] = pose; }
  std::size_t size() const { return poses_.size(); }
  // The pose at stamp_ns: exact, or interpolated between the two neighbours when they are at
  // most max_gap_ns apart; nullopt outside the track.
  std::optional<Pose2> at(StampNs stamp_ns, StampNs max_gap_ns = 20'000'000) const {
    auto hi = poses_.lower_bound(stamp_ns);
    if (hi != poses_.end() && hi->first == stamp_ns) return hi->second;
    if (hi == poses_.end() || hi == poses_.begin()) return std::nullopt;
    auto lo = std::prev(hi);
    if (hi->first - lo->first > max_gap_ns) return std::nullopt;
    const double f = static_cast<double>(stamp_ns - lo->first) / static_cast<double>(hi->first - lo->first);
    Pose2 p = lo->second + f * (hi->second - lo->second);
    p.z() = wrap_angle_rad(lo->second.z() + f * wrap_angle_rad(hi->second.z() - lo->second.z()));
    return p;
  }

 private:
  std::map<StampNs, Pose2> poses_;
};

}  // namespace beaconloc
