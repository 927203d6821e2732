// DeadlineWatch: the deadline QoS kept by a reader (core/deadline_watch.hpp).
#include "beaconloc/core/deadline_watch.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace beaconloc {
namespace {

constexpr StampNs kPeriod = 50 * kNsPerMillisecond;

std::vector<std::string> expire(DeadlineWatch<std::string>& watch, StampNs now_ns, std::uint64_t* missed = nullptr) {
  std::vector<std::string> keys;
  const std::uint64_t n = watch.expire(now_ns, [&](const std::string& key) { keys.push_back(key); });
  if (missed) *missed = n;
  return keys;
}

TEST(DeadlineWatch, AKeyMissesOncePerPeriodOfSilenceFromItsLastSample) {
  DeadlineWatch<std::string> watch(kPeriod);
  EXPECT_TRUE(expire(watch, 10 * kNsPerSecond).empty());  // nothing heard: nothing watched
  watch.on_sample("a", 0);
  watch.on_sample("b", 20 * kNsPerMillisecond);
  EXPECT_TRUE(expire(watch, kPeriod - 1).empty());
  EXPECT_EQ(expire(watch, kPeriod), std::vector<std::string>{"a"});  // a period after its sample
  EXPECT_TRUE(expire(watch, kPeriod + 10 * kNsPerMillisecond).empty());  // told once per period
  EXPECT_EQ(expire(watch, 70 * kNsPerMillisecond), std::vector<std::string>{"b"});
  // Checked every 12.5 ms for half a second: "a" misses once per period, ten in all by 0.5 s.
  int a_missed = 1;
  for (StampNs t = 75'000'000; t <= 500 * kNsPerMillisecond; t += 12'500'000) {
    for (const std::string& key : expire(watch, t)) a_missed += key == "a";
  }
  EXPECT_EQ(a_missed, 10);
}

TEST(DeadlineWatch, ASampleMovesTheDeadlineOn) {
  DeadlineWatch<std::string> watch(kPeriod);
  for (StampNs t = 0; t <= kNsPerSecond; t += 10 * kNsPerMillisecond) {
    watch.on_sample("robot", t);  // 100 Hz: never silent for a period
    EXPECT_TRUE(expire(watch, t + 5 * kNsPerMillisecond).empty()) << t;
  }
  EXPECT_EQ(expire(watch, kNsPerSecond + kPeriod), std::vector<std::string>{"robot"});
}

TEST(DeadlineWatch, AChecksGapCountsEveryPeriodMissedInOneCall) {
  DeadlineWatch<std::string> watch(kPeriod);
  watch.on_sample("a", 0);
  std::uint64_t missed = 0;
  // Not checked for 3.5 periods (the process starved): three misses, told once.
  EXPECT_EQ(expire(watch, 175 * kNsPerMillisecond, &missed), std::vector<std::string>{"a"});
  EXPECT_EQ(missed, 3u);
  // The next deadline is whole periods on from the last sample: 200 ms.
  EXPECT_TRUE(expire(watch, 199 * kNsPerMillisecond, &missed).empty());
  EXPECT_EQ(missed, 0u);
  EXPECT_EQ(expire(watch, 200 * kNsPerMillisecond, &missed).size(), 1u);
  EXPECT_EQ(missed, 1u);
  // A day unchecked is counted, not looped over.
  EXPECT_EQ(expire(watch, 86400 * kNsPerSecond, &missed).size(), 1u);
  EXPECT_EQ(missed, static_cast<std::uint64_t>((86400 * kNsPerSecond - 250 * kNsPerMillisecond) / kPeriod + 1));
}

TEST(DeadlineWatch, AForgottenKeyMissesNothingUntilItsNextSample) {
  DeadlineWatch<std::string> watch(kPeriod);
  watch.on_sample("gone", 0);
  watch.on_sample("stays", 0);
  watch.forget("gone");  // its writer ended the instance
  EXPECT_EQ(expire(watch, kNsPerSecond), std::vector<std::string>{"stays"});
  watch.on_sample("gone", kNsPerSecond);  // back: watched again
  EXPECT_EQ(expire(watch, kNsPerSecond + kPeriod), (std::vector<std::string>{"gone", "stays"}));
  watch.forget("never heard");  // nothing to forget: no effect
  EXPECT_EQ(watch.size(), 2u);
}

TEST(DeadlineWatch, APeriodThatIsNotPositiveIsRefused) {
  EXPECT_THROW(DeadlineWatch<int>(0), std::invalid_argument);
  EXPECT_THROW(DeadlineWatch<int>(-kPeriod), std::invalid_argument);
}

}  // namespace
}  // namespace beaconloc
