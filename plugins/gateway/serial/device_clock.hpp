#pragma once
// A receiver module's clock mapped to the host's (docs/serial-protocol.md, "Time"). Frames carry
// the device's free-running counter (u32 microseconds in our protocol, u32 milliseconds in
// Marvelmind's); the gateway publishes host stamps. The host sees each frame at
// arrival = device time + offset + delay, with a transport delay that is never negative, so the
// smallest arrival - device difference is the best offset. A crystal's drift makes the offset a
// slow line rather than a constant: its slope is the line under the smallest differences of the
// last minute, and the estimate is the smallest difference of the last 10 s carried along that
// slope to now. The offset applied moves toward the estimate by at most 1 % of the device time
// elapsed, so stamps keep their order. The estimator is pushed data and never reads a clock.
#include <cstdint>
#include <deque>

#include "beaconloc/core/time.hpp"

namespace beaconloc::serial {

class DeviceClock {
 public:
  // The estimate is the smallest difference of the last 10 s of device time (each carried to now
  // along the drift): long enough that a burst of late reads (a host busy for a few seconds, USB
  // latency spikes) never fills it, short enough that a change of drift has little time to tell.
  static constexpr StampNs kWindowNs = 10 * kNsPerSecond;
  // The drift is the slope of the line under the smallest differences of the last minute: a
  // crystal's drift moves with its temperature over minutes, and six times the window's span pins
  // the slope six times better than the window's own minima would (slope noise times the up to
  // 10 s it is carried over is the mapping's noise).
  static constexpr StampNs kDriftHistoryNs = 60 * kNsPerSecond;
  // One smallest difference per second of device time: at most 60 points, whatever the rate.
  static constexpr StampNs kBucketNs = kNsPerSecond;
  // The offset applied moves by at most 1/100 of the device time elapsed: 100 times any real
  // crystal's drift, and mapped stamps advance by at least 99 % of the device's.
  static constexpr std::int64_t kSlewDivisor = 100;
  // A difference more than 1 s below the applied offset (the device's time ran ahead of the
  // host's: a reset whose counter restarted past the wrap point, another device), a counter more
  // than 1 s behind the newest, or an estimate more than 1 s above the applied offset for a whole
  // window: the mapping starts again, counted. No crystal and no USB delay explains 1 s.
  static constexpr StampNs kStepLimitNs = kNsPerSecond;
  // A slope steeper than 1000 ppm is no crystal's drift (too few or too noisy minima): no drift is
  // assumed instead (the plain window minimum).
  static constexpr double kMaxDriftRate = 1e-3;

  struct Counts {
    std::uint64_t samples = 0;
    std::uint64_t clock_resets = 0;
    // A counter behind the newest by at most kStepLimitNs (a TOF's fire time before the latest
    // heartbeat's stamp): mapped with the offset applied now, not used for the estimate.
    std::uint64_t behind_newest = 0;
  };

  // tick_ns: the counter's period (1'000 for microseconds); counter_modulus: where it wraps
  // (2^32 for a u32). Throws std::invalid_argument for a tick or modulus of 0 or below 2.
  DeviceClock(std::int64_t tick_ns, std::uint64_t counter_modulus);

  // The host stamp of the device time `counter` (< counter_modulus, else std::invalid_argument),
  // seen in a frame that arrived at arrival_ns. Strictly increasing while the counter advances.
  StampNs map(std::uint64_t counter, StampNs arrival_ns);

  // Forgets the device (the port reopened: maybe another device): not counted as a clock reset.
  void reset();

  const Counts& counts() const { return counts_; }

 private:
  struct Bucket {
    std::int64_t index = 0;  // device_ns / kBucketNs
    StampNs device_ns = 0;   // of the smallest difference in the bucket
    StampNs difference_ns = 0;
  };

  StampNs start(std::uint64_t counter, StampNs arrival_ns);
  void add(StampNs device_ns, StampNs difference_ns);
  void fit_drift();
  StampNs estimate(StampNs device_ns) const;

  std::int64_t tick_ns_;
  std::uint64_t modulus_;
  bool started_ = false;
  std::uint64_t newest_counter_ = 0;
  StampNs newest_device_ns_ = 0;
  StampNs applied_offset_ns_ = 0;
  std::deque<Bucket> buckets_;  // the last kDriftHistoryNs / kBucketNs, oldest first
  double drift_ = 0.0;          // ns of offset per ns of device time
  Counts counts_;
};

}  // namespace beaconloc::serial
