// RangeNoiseScale (issue 18, item 3): the ranges' noise learnt as k times the declared sigma from
// the median of the innovations; k found whichever side the declared sigma is wrong, barely moved
// by a tenth of outliers (they count as votes, not as squares), and bounded.
#include "beaconloc/core/models/range_noise_scale.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace beaconloc {
namespace {

// The scale learnt from n innovations of sigma true_sigma_m (plus state_m2 of the state's share),
// declared as declared_sigma_m, a fraction of them outliers 1-10 m long; the mean over the last
// half (a constant-step tracker fluctuates around its target).
double learnt_scale(double true_sigma_m, double declared_sigma_m, double outliers, int n = 20000) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double state_m2 = 0.02 * 0.02;
  RangeNoiseScale scale;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    double innovation_m = std::sqrt(state_m2 + true_sigma_m * true_sigma_m) * noise(rng);
    if (uniform(rng) < outliers) innovation_m = 1.0 + 9.0 * uniform(rng);
    scale.learn(innovation_m, state_m2, declared_sigma_m * declared_sigma_m);
    if (i >= n / 2) sum += scale.scale();
  }
  EXPECT_EQ(scale.ranges_learnt(), static_cast<std::uint64_t>(n));
  return sum / (n / 2);
}

TEST(RangeNoiseScale, LearnsTheSigmaWhicheverSideTheDeclaredOneIsWrong) {
  EXPECT_NEAR(learnt_scale(0.1, 0.1, 0.0), 1.0, 0.05);
  EXPECT_NEAR(learnt_scale(0.3, 0.1, 0.0), 3.0, 0.15);
  EXPECT_NEAR(learnt_scale(0.1, 0.3, 0.0), 1.0 / 3.0, 0.03);
}

TEST(RangeNoiseScale, ATenthOfOutliersMovesItLittleAndAVarianceWouldMoveItMuch) {
  // A tenth outside: the median is the inliers' 0.444 quantile, 0.765 sigma: k 13 % high.
  const double k = learnt_scale(0.1, 0.1, 0.1);
  EXPECT_GT(k, 1.05);
  EXPECT_LT(k, 1.2);
  // The same outliers' mean square (about 33 m^2 a tenth) would put k near 60.
}

TEST(RangeNoiseScale, StaysWithinItsBoundsAndIgnoresWhatIsNotFinite) {
  const double high = learnt_scale(10.0, 0.1, 0.0, 2000);  // at its bound, stepping off and back
  EXPECT_LE(high, 4.0 + 1e-12);
  EXPECT_GT(high, 3.99);
  const double low = learnt_scale(0.001, 0.1, 0.0, 2000);
  EXPECT_GE(low, 0.25 - 1e-12);
  EXPECT_LT(low, 0.253);
  RangeNoiseScale scale;
  scale.learn(std::nan(""), 0.0, 0.01);
  scale.learn(0.1, -1.0, 0.01);
  scale.learn(0.1, 0.0, 0.0);
  scale.learn(INFINITY, 0.0, 0.01);
  EXPECT_EQ(scale.ranges_learnt(), 0u);
  EXPECT_EQ(scale.scale(), 1.0);
  EXPECT_THROW(RangeNoiseScale(0.0), std::invalid_argument);
  EXPECT_THROW(RangeNoiseScale(0.02, 2.0, 4.0), std::invalid_argument);
}

}  // namespace
}  // namespace beaconloc
