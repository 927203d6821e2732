#include "device_clock.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace beaconloc::serial {
namespace {

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

}  // namespace

DeviceClock::DeviceClock(std::int64_t tick_ns, std::uint64_t counter_modulus)
    : tick_ns_(tick_ns), modulus_(counter_modulus) {
  if (tick_ns <= 0) throw std::invalid_argument("DeviceClock: the tick must be positive");
  if (counter_modulus < 2) throw std::invalid_argument("DeviceClock: the counter modulus must be at least 2");
  // Half the range, in ns, must fit the int64 device time with room for years of wraps.
  if (static_cast<double>(counter_modulus) * static_cast<double>(tick_ns) > 1e18) {
    throw std::invalid_argument("DeviceClock: a counter range beyond 30 years");
  }
}

void DeviceClock::reset() {
  started_ = false;
  buckets_.clear();
  drift_ = 0.0;
}

StampNs DeviceClock::start(std::uint64_t counter, StampNs arrival_ns) {
  started_ = true;
  newest_counter_ = counter;
  newest_device_ns_ = static_cast<StampNs>(counter) * tick_ns_;
  applied_offset_ns_ = arrival_ns - newest_device_ns_;
  buckets_.clear();
  drift_ = 0.0;
  add(newest_device_ns_, applied_offset_ns_);
  return arrival_ns;
}

StampNs DeviceClock::map(std::uint64_t counter, StampNs arrival_ns) {
  if (counter >= modulus_) throw std::invalid_argument("DeviceClock: a counter beyond its modulus");
  ++counts_.samples;
  if (!started_) return start(counter, arrival_ns);

  // Forward by up to half the range (a wrap included), else backwards.
  const std::uint64_t forward =
      counter >= newest_counter_ ? counter - newest_counter_ : counter + (modulus_ - newest_counter_);
  if (forward > modulus_ / 2) {
    const StampNs back_ns = static_cast<StampNs>(modulus_ - forward) * tick_ns_;
    if (back_ns > kStepLimitNs) {
      ++counts_.clock_resets;
      return start(counter, arrival_ns);
    }
    ++counts_.behind_newest;
    return newest_device_ns_ - back_ns + applied_offset_ns_;
  }

  const StampNs device_ns = newest_device_ns_ + static_cast<StampNs>(forward) * tick_ns_;
  const StampNs difference_ns = arrival_ns - device_ns;
  if (difference_ns < applied_offset_ns_ - kStepLimitNs) {  // a delay below -1 s: not this time line
    ++counts_.clock_resets;
    return start(counter, arrival_ns);
  }
  add(device_ns, difference_ns);
  const StampNs target_ns = estimate(device_ns);
  if (target_ns > applied_offset_ns_ + kStepLimitNs) {  // every difference of the window 1 s later
    ++counts_.clock_resets;
    return start(counter, arrival_ns);
  }
  const StampNs max_step_ns = (device_ns - newest_device_ns_) / kSlewDivisor;
  applied_offset_ns_ += std::clamp(target_ns - applied_offset_ns_, -max_step_ns, max_step_ns);
  newest_counter_ = counter;
  newest_device_ns_ = device_ns;
  return device_ns + applied_offset_ns_;
}

void DeviceClock::add(StampNs device_ns, StampNs difference_ns) {
  const std::int64_t index = floor_div(device_ns, kBucketNs);
  if (!buckets_.empty() && buckets_.back().index == index) {
    if (difference_ns < buckets_.back().difference_ns) buckets_.back() = {index, device_ns, difference_ns};
    return;
  }
  // A bucket is complete: the slope is fitted again over the complete ones, once a second.
  fit_drift();
  buckets_.push_back({index, device_ns, difference_ns});
  constexpr std::int64_t kBuckets = kDriftHistoryNs / kBucketNs;
  while (buckets_.front().index <= index - kBuckets) buckets_.pop_front();
}

// The line under every bucket's minimum that lies closest to them (the sum of the minima's
// heights above it is smallest: the linear-programming skew estimate of Moon, Skelly and Towsley,
// 1999). Delays only ever lift a point, so late bursts cannot tilt it. The sum of heights is
// n * (mean y - line(mean x)): the best line is the one highest at the mean x among those under
// every point, the edge of the points' lower convex hull that spans the mean x.
void DeviceClock::fit_drift() {
  drift_ = 0.0;
  if (buckets_.size() < 2) return;
  const StampNs x0 = buckets_.front().device_ns;
  const StampNs y0 = buckets_.front().difference_ns;
  struct Point {
    double x;  // s since the first point
    double y;  // ns above the first point
  };
  std::vector<Point> hull;
  double mean_x = 0.0;
  for (const Bucket& b : buckets_) {  // by increasing device time
    const Point p{static_cast<double>(b.device_ns - x0) * 1e-9, static_cast<double>(b.difference_ns - y0)};
    mean_x += p.x;
    // Keep only left turns: the middle point of a right turn or a straight line is above the hull.
    while (hull.size() >= 2) {
      const Point& o = hull[hull.size() - 2];
      const Point& a = hull.back();
      if ((a.x - o.x) * (p.y - o.y) - (a.y - o.y) * (p.x - o.x) > 0.0) break;
      hull.pop_back();
    }
    hull.push_back(p);
  }
  mean_x /= static_cast<double>(buckets_.size());
  for (std::size_t i = 0; i + 1 < hull.size(); ++i) {
    if (hull[i + 1].x < mean_x) continue;
    const double slope = (hull[i + 1].y - hull[i].y) / (hull[i + 1].x - hull[i].x) * 1e-9;  // ns per ns
    if (std::isfinite(slope) && std::abs(slope) <= kMaxDriftRate) drift_ = slope;
    return;
  }
}

// The smallest difference of the window, each carried from its device time to device_ns along
// the drift.
StampNs DeviceClock::estimate(StampNs device_ns) const {
  constexpr std::int64_t kWindowBuckets = kWindowNs / kBucketNs;
  const std::int64_t index = floor_div(device_ns, kBucketNs);
  StampNs best = std::numeric_limits<StampNs>::max();
  for (auto b = buckets_.rbegin(); b != buckets_.rend() && b->index > index - kWindowBuckets; ++b) {
    const auto carried =
        static_cast<StampNs>(std::llround(drift_ * static_cast<double>(device_ns - b->device_ns)));
    best = std::min(best, b->difference_ns + carried);
  }
  return best;
}

}  // namespace beaconloc::serial
