// The odometry time line's gap (core/odometry_timeline.hpp): an interval longer than max_gap_s,
// or than kGapPeriods of a slower sensor's own period (the median of its recent intervals), is
// not integrated; the period a stream can teach stops at kMaxLearntGapS.
#include "beaconloc/core/odometry_timeline.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace beaconloc {
namespace {

constexpr double kMaxGapS = kDefaultMaxOdometryGapS;

class Stream {
 public:
  // The outcome of one more sample, interval_s after the one before.
  OdometryTimeline::Step after(double interval_s) {
    sample_.stamp_ns += s_to_ns(interval_s);
    return timeline_.advance(sample_);
  }
  // Samples every interval_s, count of them, each integrated (else the test fails there).
  void integrated(double interval_s, int count) {
    for (int k = 0; k < count; ++k) ASSERT_TRUE(after(interval_s).integrate) << interval_s << " s, sample " << k;
  }
  const OdometryTimeline& timeline() const { return timeline_; }

 private:
  OdometryTimeline timeline_{kMaxGapS};
  OdometrySample sample_ = [] {
    OdometrySample o;
    o.wheel_base_m = 0.4;
    return o;
  }();
};

TEST(OdometryTimeline, At100HzAGapIsMaxGapS) {
  Stream s;
  ASSERT_TRUE(s.after(0.0).result.accepted);  // the anchor
  s.integrated(0.01, 50);
  EXPECT_DOUBLE_EQ(s.timeline().gap_limit_s(), kMaxGapS);  // 4 periods are 0.04 s: max_gap_s rules
  EXPECT_TRUE(s.after(0.19).integrate);
  const OdometryTimeline::Step gap = s.after(0.21);
  EXPECT_FALSE(gap.integrate);
  EXPECT_EQ(gap.result.rejection, Rejection::kOdometryGap);
  s.integrated(0.01, 3);  // and on from there
}

TEST(OdometryTimeline, ASlowerSensorsOwnPeriodSetsItsGap) {
  Stream s;
  ASSERT_TRUE(s.after(0.0).result.accepted);
  // Before kMinPeriodSamples intervals, only max_gap_s is known.
  EXPECT_EQ(s.after(0.21).result.rejection, Rejection::kOdometryGap);
  s.integrated(0.19, 1);
  // The CMU mower's 5 Hz odometry, every 0.17-0.23 s: none of it a gap.
  const std::vector<double> jittered = {0.17, 0.23, 0.2, 0.21, 0.19, 0.22, 0.18, 0.2};
  for (int round = 0; round < 3; ++round) {
    for (const double interval_s : jittered) ASSERT_TRUE(s.after(interval_s).integrate) << interval_s;
  }
  EXPECT_NEAR(s.timeline().gap_limit_s(), OdometryTimeline::kGapPeriods * 0.2, 1e-9);
  EXPECT_TRUE(s.after(0.75).integrate);  // three samples lost
  EXPECT_EQ(s.after(0.85).result.rejection, Rejection::kOdometryGap);
  // A gap or two do not teach the median a longer period.
  EXPECT_EQ(s.after(0.85).result.rejection, Rejection::kOdometryGap);
  EXPECT_NEAR(s.timeline().gap_limit_s(), OdometryTimeline::kGapPeriods * 0.2, 1e-9);
}

TEST(OdometryTimeline, AStreamCannotTeachAGapBeyondTheLearntLimit) {
  Stream s;
  ASSERT_TRUE(s.after(0.0).result.accepted);
  // Samples 2 s apart: the median period is 2 s, but velocities held that long invent motion.
  for (int k = 0; k < 20; ++k) {
    EXPECT_EQ(s.after(2.0).result.rejection, Rejection::kOdometryGap) << "sample " << k;
  }
  EXPECT_DOUBLE_EQ(s.timeline().gap_limit_s(), OdometryTimeline::kMaxLearntGapS);
  EXPECT_TRUE(s.after(0.9).integrate);
  // A faster stream again is learnt again.
  s.integrated(0.01, static_cast<int>(OdometryTimeline::kPeriodSamples));
  EXPECT_DOUBLE_EQ(s.timeline().gap_limit_s(), kMaxGapS);
}

TEST(OdometryTimeline, MaxGapSIsAFloorTheLearntLimitOnlyRelaxes) {
  OdometryTimeline generous(2.0);  // a user's max_odometry_gap_s beyond kMaxLearntGapS
  OdometrySample o;
  o.wheel_base_m = 0.4;
  ASSERT_TRUE(generous.advance(o).result.accepted);
  for (int k = 0; k < 20; ++k) {
    o.stamp_ns += s_to_ns(0.01);
    ASSERT_TRUE(generous.advance(o).integrate);
  }
  EXPECT_DOUBLE_EQ(generous.gap_limit_s(), 2.0);
  o.stamp_ns += s_to_ns(1.5);
  EXPECT_TRUE(generous.advance(o).integrate);
  o.stamp_ns += s_to_ns(2.5);
  EXPECT_EQ(generous.advance(o).result.rejection, Rejection::kOdometryGap);
}

}  // namespace
}  // namespace beaconloc
