// DeviceClock (plugins/gateway/serial/device_clock.hpp) against simulated lines: a device clock
// with a known offset and drift, frames seen after random non-negative delays. Mapped stamps stay
// within the smallest delay of the truth, follow +-100 ppm of drift within 1 ms, cross the u32
// wrap without a step, start again (counted) after a device reset, and are strictly increasing
// whenever device times are, in every case.
#include "device_clock.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace beaconloc::serial {
namespace {

constexpr std::int64_t kUs = 1'000;
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kS = 1'000'000'000;
constexpr std::uint64_t kU32 = 1ull << 32;

// A line: the device's counter at each frame, when the host saw it, and the truth (the host time
// at which the device's counter read that value).
class Line {
 public:
  Line(std::int64_t tick_ns, std::uint64_t seed) : tick_ns_(tick_ns), random_(seed) {}

  // Transport delay: at least min_delay_ns, plus an exponential tail (USB polling, the reader's
  // scheduling) of mean tail_ns, capped at 50 ms.
  std::int64_t delay(std::int64_t min_delay_ns, double tail_ns) {
    const double extra = std::exponential_distribution<double>(1.0 / tail_ns)(random_);
    return min_delay_ns + static_cast<std::int64_t>(std::min(extra, 50e6));
  }
  std::int64_t jitter(std::int64_t max_ns) {
    return std::uniform_int_distribution<std::int64_t>(0, max_ns)(random_);
  }
  std::int64_t tick_ns() const { return tick_ns_; }

 private:
  std::int64_t tick_ns_;
  std::mt19937_64 random_;
};

struct Tally {
  std::int64_t min_error_ns = INT64_MAX;
  std::int64_t max_error_ns = INT64_MIN;
  bool increasing = true;
  StampNs last_mapped = INT64_MIN;
  std::int64_t last_device = INT64_MIN;

  void add(std::int64_t device_ticks, StampNs mapped, StampNs truth, bool judge) {
    if (last_device != INT64_MIN && device_ticks > last_device && mapped <= last_mapped) increasing = false;
    last_device = device_ticks;
    last_mapped = mapped;
    if (!judge) return;
    min_error_ns = std::min(min_error_ns, mapped - truth);
    max_error_ns = std::max(max_error_ns, mapped - truth);
  }
};

constexpr std::int64_t kMinDelay = 300 * kUs;

// A device running ppm fast or slow against the host, sampled every period_ns of device time
// (with jitter), counter starting at start_ticks; errors judged after the first window.
Tally run(DeviceClock& clock, Line& line, std::int64_t start_ticks, std::int64_t duration_ns,
          std::int64_t period_ns, double ppm, std::uint64_t modulus, StampNs host_offset_ns) {
  Tally tally;
  for (std::int64_t t = 0; t < duration_ns; t += period_ns) {
    const std::int64_t device_ns = t + line.jitter(period_ns / 2) / line.tick_ns() * line.tick_ns();
    const std::int64_t ticks = start_ticks + device_ns / line.tick_ns();
    const StampNs truth =
        host_offset_ns + device_ns +
        static_cast<std::int64_t>(std::llround(static_cast<double>(device_ns) * ppm * 1e-6));
    const StampNs arrival = truth + line.delay(kMinDelay, 2.0e6);
    const StampNs mapped = clock.map(static_cast<std::uint64_t>(ticks) % modulus, arrival);
    tally.add(ticks, mapped, truth, t >= DeviceClock::kWindowNs);
  }
  return tally;
}

// Constant offset, random delays of at least 0.3 ms: once the window has filled, every stamp is
// within the smallest delay of the truth (late by it, the offset being the smallest difference).
TEST(SerialDeviceClock, AConstantOffsetIsMappedWithinTheSmallestDelayOfTheTruth) {
  DeviceClock clock(kUs, kU32);
  Line line(kUs, 1);
  const Tally tally = run(clock, line, 123456789, 120 * kS, 10 * kMs, 0.0, kU32, 1'700'000'000 * kS);
  EXPECT_TRUE(tally.increasing);
  EXPECT_GE(tally.min_error_ns, 0);
  EXPECT_LE(tally.max_error_ns, kMinDelay + 20 * kUs);
  EXPECT_EQ(clock.counts().clock_resets, 0u);
  EXPECT_EQ(clock.counts().samples, 12000u);
}

// Crystals of +-100 ppm: over ten minutes the mapping follows within 1 ms (the smallest delay
// included), without a step.
TEST(SerialDeviceClock, DriftOfAHundredPpmEitherWayIsFollowedWithinAMillisecond) {
  for (double ppm : {100.0, -100.0}) {
    SCOPED_TRACE(ppm);
    DeviceClock clock(kUs, kU32);
    Line line(kUs, 2);
    const Tally tally = run(clock, line, 0, 600 * kS, 20 * kMs, ppm, kU32, 5 * kS);
    EXPECT_TRUE(tally.increasing);
    EXPECT_GE(tally.min_error_ns, -1 * kMs);
    EXPECT_LE(tally.max_error_ns, 1 * kMs);
    EXPECT_EQ(clock.counts().clock_resets, 0u);
  }
}

// A heartbeat-only line (10 Hz) still follows the drift.
TEST(SerialDeviceClock, HeartbeatsAloneFollowTheDriftWithinAMillisecond) {
  DeviceClock clock(kUs, kU32);
  Line line(kUs, 3);
  const Tally tally = run(clock, line, 42, 600 * kS, 100 * kMs, 100.0, kU32, 5 * kS);
  EXPECT_TRUE(tally.increasing);
  EXPECT_GE(tally.min_error_ns, -1 * kMs);
  EXPECT_LE(tally.max_error_ns, 1 * kMs);
}

// The u32 microsecond counter wraps every 71.6 minutes, Marvelmind's millisecond one every 49.7
// days: both are crossed without a step.
TEST(SerialDeviceClock, TheCounterWrapsWithoutAStep) {
  {
    DeviceClock clock(kUs, kU32);
    Line line(kUs, 4);
    const std::int64_t start = static_cast<std::int64_t>(kU32) - 30 * kS / kUs;  // 30 s before the wrap
    const Tally tally = run(clock, line, start, 60 * kS, 10 * kMs, 50.0, kU32, 7 * kS);
    EXPECT_TRUE(tally.increasing);
    EXPECT_GE(tally.min_error_ns, 0);
    EXPECT_LE(tally.max_error_ns, kMinDelay + 200 * kUs);
    EXPECT_EQ(clock.counts().clock_resets, 0u);
  }
  {
    DeviceClock clock(kMs, kU32);
    Line line(kMs, 5);
    const std::int64_t start = static_cast<std::int64_t>(kU32) - 30 * kS / kMs;
    const Tally tally = run(clock, line, start, 60 * kS, 50 * kMs, 0.0, kU32, 7 * kS);
    EXPECT_TRUE(tally.increasing);
    EXPECT_GE(tally.min_error_ns, -1 * kMs);  // stamps of whole milliseconds
    EXPECT_LE(tally.max_error_ns, kMinDelay + 1 * kMs);
    EXPECT_EQ(clock.counts().clock_resets, 0u);
  }
}

// The device resets after 100 s: its counter starts again at 0, the host's time goes on. The
// step is counted once, the first stamp after it is its arrival, and the new time line is
// followed as well as the first.
TEST(SerialDeviceClock, ADeviceResetIsCountedAndMappedAfresh) {
  DeviceClock clock(kUs, kU32);
  Line line(kUs, 6);
  const Tally before = run(clock, line, 1000, 100 * kS, 10 * kMs, 0.0, kU32, 50 * kS);
  EXPECT_TRUE(before.increasing);
  EXPECT_EQ(clock.counts().clock_resets, 0u);
  const StampNs arrival = 153 * kS + kMinDelay;  // the new time line: counter 0 at 153 s
  EXPECT_EQ(clock.map(0, arrival), arrival);
  EXPECT_EQ(clock.counts().clock_resets, 1u);
  const Tally after = run(clock, line, 0, 100 * kS, 10 * kMs, 0.0, kU32, 153 * kS);
  EXPECT_TRUE(after.increasing);
  EXPECT_GE(after.min_error_ns, 0);
  EXPECT_LE(after.max_error_ns, kMinDelay + 20 * kUs);
  EXPECT_EQ(clock.counts().clock_resets, 1u);
}

// A reset when the counter stood beyond half its range: 0 reads as a jump ahead across the wrap
// (device time far ahead of the host's: a negative delay), counted as a reset too.
TEST(SerialDeviceClock, ARestartThatLooksLikeAJumpAheadIsAResetToo) {
  DeviceClock clock(kUs, kU32);
  Line line(kUs, 7);
  const std::int64_t late = 3000 * kS / kUs;  // 50 minutes: past half the u32's 71.6
  run(clock, line, late, 20 * kS, 10 * kMs, 0.0, kU32, 9 * kS);
  const StampNs arrival = 9 * kS + 3000 * kS + 25 * kS;
  EXPECT_EQ(clock.map(5, arrival), arrival);
  EXPECT_EQ(clock.counts().clock_resets, 1u);
}

// A counter slightly behind the newest (a TOF's fire time before the latest heartbeat): mapped
// on the same offset, not a reset, and the mapping goes on undisturbed.
TEST(SerialDeviceClock, ACounterSlightlyBehindTheNewestIsMappedOnTheSameOffset) {
  DeviceClock clock(kUs, kU32);
  Line line(kUs, 8);
  run(clock, line, 0, 20 * kS, 10 * kMs, 0.0, kU32, 9 * kS);
  const StampNs newest = clock.map(20'000'000, 9 * kS + 20 * kS + kMinDelay);
  const StampNs behind = clock.map(20'000'000 - 30'000, 9 * kS + 20 * kS + 5 * kMs);
  EXPECT_EQ(newest - behind, 30 * kMs);
  EXPECT_EQ(clock.counts().behind_newest, 1u);
  EXPECT_EQ(clock.counts().clock_resets, 0u);
  // More than the step limit behind (and less than half the range): a reset.
  clock.map(20'000'000 - 2'000'000, 9 * kS + 20 * kS + 6 * kMs);
  EXPECT_EQ(clock.counts().clock_resets, 1u);
}

// The host stops reading for 3 s and then reads the backlog at once: those frames arrive seconds
// late, yet are mapped on the device's clock (within the smallest delay of the truth), and the
// mapping is not moved by them.
TEST(SerialDeviceClock, ABacklogReadLateDoesNotMoveTheMapping) {
  DeviceClock clock(kUs, kU32);
  Line line(kUs, 9);
  const StampNs offset = 11 * kS;
  run(clock, line, 0, 30 * kS, 10 * kMs, 0.0, kU32, offset);
  Tally tally;
  for (std::int64_t t = 30 * kS; t < 60 * kS; t += 10 * kMs) {
    const StampNs truth = offset + t;
    const bool stalled = t < 33 * kS;
    const StampNs arrival =
        stalled ? offset + 33 * kS + (t - 30 * kS) / 1000 : truth + line.delay(kMinDelay, 2e6);
    tally.add(t / kUs, clock.map(static_cast<std::uint64_t>(t / kUs), arrival), truth, true);
  }
  EXPECT_TRUE(tally.increasing);
  EXPECT_GE(tally.min_error_ns, 0);
  EXPECT_LE(tally.max_error_ns, kMinDelay + 20 * kUs);
  EXPECT_EQ(clock.counts().clock_resets, 0u);
}

// Started on a slow first frame (40 ms late), the mapping slews down to the truth at no more than
// 1 % of the time elapsed: strictly increasing stamps all along.
TEST(SerialDeviceClock, AFirstLateFrameIsSlewedAwayWithoutAStepBack) {
  DeviceClock clock(kUs, kU32);
  const StampNs offset = 3 * kS;
  StampNs last = clock.map(0, offset + 40 * kMs);
  for (std::int64_t t = 1 * kMs; t < 20 * kS; t += 1 * kMs) {
    const StampNs mapped = clock.map(static_cast<std::uint64_t>(t / kUs), offset + t + kMinDelay);
    ASSERT_GT(mapped, last) << t;
    ASSERT_GE(mapped - last, (1 * kMs) * 99 / 100) << t;
    last = mapped;
  }
  EXPECT_LE(last - (offset + 20 * kS - 1 * kMs), kMinDelay + 1 * kUs);
}

// reset() forgets the device (a reopened port): the next frame starts the mapping, uncounted.
TEST(SerialDeviceClock, ResetForgetsTheDeviceWithoutCountingAClockReset) {
  DeviceClock clock(kUs, kU32);
  clock.map(1000, 5 * kS);
  clock.map(2000, 5 * kS + 1 * kMs);
  clock.reset();
  EXPECT_EQ(clock.map(77, 90 * kS), 90 * kS);
  EXPECT_EQ(clock.counts().clock_resets, 0u);
  EXPECT_THROW(clock.map(kU32, 0), std::invalid_argument);
  EXPECT_THROW(DeviceClock(0, kU32), std::invalid_argument);
}

}  // namespace
}  // namespace beaconloc::serial
