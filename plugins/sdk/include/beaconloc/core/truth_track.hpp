#pragma once
// Ground-truth poses by stamp, looked up at the stamps of estimates. Some recordings have no
// heading: each sample says whether its yaw is known.
#include <cstdint>
#include <iterator>
#include <map>
#include <optional>

#include "beaconloc/core/pose2.hpp"
#include "beaconloc/core/time.hpp"

namespace beaconloc {

struct TruthSample {
  Pose2 pose_map_base = Pose2::Zero();
  bool has_yaw = true;
};

class TruthTrack {
 public:
  void add(StampNs stamp_ns, const Pose2& pose, bool has_yaw = true) { samples_[stamp_ns] = {pose, has_yaw}; }
  std::size_t size() const { return samples_.size(); }
  bool empty() const { return samples_.empty(); }
  const std::map<StampNs, TruthSample>& samples() const { return samples_; }
  // The truth at stamp_ns: exact, or interpolated between the two neighbours when they are at
  // most max_gap_ns apart (yaw known only if known at both); nullopt outside the track.
  std::optional<TruthSample> at(StampNs stamp_ns, StampNs max_gap_ns = 20'000'000) const {
    auto hi = samples_.lower_bound(stamp_ns);
    if (hi != samples_.end() && hi->first == stamp_ns) return hi->second;
    if (hi == samples_.end() || hi == samples_.begin()) return std::nullopt;
    auto lo = std::prev(hi);
    // hi > lo: as unsigned, their distance never overflows (stamps at both ends of the clock).
    const std::uint64_t gap = static_cast<std::uint64_t>(hi->first) - static_cast<std::uint64_t>(lo->first);
    if (max_gap_ns < 0 || gap > static_cast<std::uint64_t>(max_gap_ns)) return std::nullopt;
    const double f = static_cast<double>(stamp_ns - lo->first) / static_cast<double>(hi->first - lo->first);
    const Pose2& a = lo->second.pose_map_base;
    const Pose2& b = hi->second.pose_map_base;
    TruthSample out;
    out.pose_map_base = a + f * (b - a);
    out.pose_map_base.z() = wrap_angle_rad(a.z() + f * wrap_angle_rad(b.z() - a.z()));
    out.has_yaw = lo->second.has_yaw && hi->second.has_yaw;
    return out;
  }

 private:
  std::map<StampNs, TruthSample> samples_;
};

}  // namespace beaconloc
