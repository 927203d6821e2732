// Seed 003 Sec. 3.5 (scan/similarity_transform.hpp): the local -> global similarity of a group,
// analytic (eq. 39-43) and numerical (eq. 44-47), against transforms known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "scan/similarity_transform.hpp"

namespace beaconloc::scan {
namespace {

// A group's frame rotated by 0.7 rad, scaled by 1.02 and moved to (20, -3).
Similarity2 truth() {
  const double scale = 1.02, angle = 0.7;
  return Similarity2{Eigen::Vector4d(scale * std::cos(angle), scale * std::sin(angle), 20.0, -3.0)};
}

PointPair pair_at(const Eigen::Vector2d& local_m, const Similarity2& s = truth()) { return {local_m, s.apply(local_m)}; }

TEST(SimilarityTransform, ApplyIsEquations42And43) {
  const Similarity2 s{Eigen::Vector4d(0.5, 2.0, 3.0, 4.0)};
  const Eigen::Vector2d p = s.apply({1.0, -1.0});
  EXPECT_DOUBLE_EQ(p.x(), 1.0 * 0.5 - (-1.0) * 2.0 + 3.0);  // eq. 42
  EXPECT_DOUBLE_EQ(p.y(), -1.0 * 0.5 + 1.0 * 2.0 + 4.0);    // eq. 43
  EXPECT_NEAR(truth().scale(), 1.02, 1e-12);
  EXPECT_NEAR(truth().rotation_rad(), 0.7, 1e-12);
}

TEST(SimilarityTransform, TwoPointsGiveTheTransformExactly) {
  const TransformFit fit = analytic_similarity(pair_at({3.0, 1.0}), pair_at({0.5, -0.5}), 2.5);
  ASSERT_EQ(fit.failure, TransformFailure::kNone);
  EXPECT_TRUE(fit.transform->t_c.isApprox(truth().t_c, 1e-12)) << fit.transform->t_c.transpose();
  EXPECT_LT(fit.mean_error_m, 1e-12);
}

TEST(SimilarityTransform, TwoPointsCloserThanDminOrNotFiniteAreRefused) {
  EXPECT_EQ(analytic_similarity(pair_at({1.0, 1.0}), pair_at({2.0, 1.0}), 2.5).failure,
            TransformFailure::kPointsTooClose);
  EXPECT_EQ(analytic_similarity(pair_at({1.0, 1.0}), pair_at({1.0, 1.0}), 0.0).failure, TransformFailure::kSingular);
  PointPair nan = pair_at({5.0, 1.0});
  nan.global_m.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(analytic_similarity(pair_at({1.0, 1.0}), nan, 2.5).failure, TransformFailure::kNonFinite);
  EXPECT_FALSE(analytic_similarity(pair_at({1.0, 1.0}), nan, 2.5).transform);
}

// A straight drive through the overlap, both frames' estimates with 2 cm of noise.
std::vector<PointPair> noisy_track(std::mt19937_64& rng, double sigma_m) {
  std::normal_distribution<double> noise(0.0, sigma_m);
  std::vector<PointPair> track;
  for (int k = 0; k <= 500; ++k) {  // 5 m at 1 cm a step
    const Eigen::Vector2d local(-2.5 + 0.01 * k, 0.3 + 0.002 * k);
    PointPair p = pair_at(local);
    p.local_m += Eigen::Vector2d(noise(rng), noise(rng));
    p.global_m += Eigen::Vector2d(noise(rng), noise(rng));
    track.push_back(p);
  }
  return track;
}

// Where the transform takes a beacon 1 m from the group's origin, against the truth.
double beacon_error_m(const Similarity2& s) {
  const Eigen::Vector2d beacon(0.35, 0.35);
  return (s.apply(beacon) - truth().apply(beacon)).norm();
}

TEST(SimilarityTransform, TheAverageOverTheOverlapIsCloserThanOnePair) {
  std::mt19937_64 rng(3);
  const std::vector<PointPair> track = noisy_track(rng, 0.02);
  AnalyticAverage average(2.5);
  EXPECT_EQ(average.average().failure, TransformFailure::kTooFewPoints);
  std::size_t added = 0;
  for (const PointPair& p : track) added += average.add(p) == TransformFailure::kNone;
  EXPECT_EQ(added, average.count());
  EXPECT_GT(average.count(), 200u);  // every pair past the first 2.5 m
  const TransformFit mean = average.average();
  ASSERT_EQ(mean.failure, TransformFailure::kNone);
  const TransformFit one = analytic_similarity(track.back(), track[track.size() - 260], 2.5);
  ASSERT_EQ(one.failure, TransformFailure::kNone);
  EXPECT_LT(beacon_error_m(*mean.transform), 0.02);
  EXPECT_LT(beacon_error_m(*mean.transform), beacon_error_m(*one.transform));
}

TEST(SimilarityTransform, TheAverageLeavesOutAVectorWhoseScaleNoFrameInMetresHas) {
  AnalyticAverage average(2.5);
  EXPECT_EQ(average.add(pair_at({0.0, 0.0})), TransformFailure::kTooFewPoints);
  EXPECT_EQ(average.add(pair_at({3.0, 0.0})), TransformFailure::kNone);  // scale 1.02
  // A pair whose global point is 1 m off (a fix an echo moved): its vector's scale is 1.35.
  PointPair wrong = pair_at({6.0, 0.0});
  wrong.global_m += Eigen::Vector2d(std::cos(0.7), std::sin(0.7));
  EXPECT_EQ(average.add(wrong), TransformFailure::kImplausibleScale);
  EXPECT_EQ(average.count(), 1u);
  EXPECT_TRUE(average.average().transform->t_c.isApprox(truth().t_c, 1e-9));
  EXPECT_STREQ(to_string(TransformFailure::kImplausibleScale), "implausible_scale");
}

TEST(SimilarityTransform, TheNumericalFitRecoversAnExactTransformAndSpreadsItsPoints) {
  std::vector<PointPair> track;
  for (int k = 0; k <= 500; ++k) track.push_back(pair_at({-2.5 + 0.01 * k, 0.3 + 0.002 * k}));
  const std::vector<PointPair> points = spread_points(track, 1.0, 10);
  ASSERT_EQ(points.size(), 6u);  // 5.1 m of track, points just over 1 m apart: 0, 1.01, ... 5.05 m
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t j = i + 1; j < points.size(); ++j) EXPECT_GT((points[i].local_m - points[j].local_m).norm(), 1.0);
  }
  EXPECT_EQ(points.front().local_m, track.back().local_m);  // newest first
  const TransformFit fit = numerical_similarity(points);
  ASSERT_EQ(fit.failure, TransformFailure::kNone);
  EXPECT_TRUE(fit.transform->t_c.isApprox(truth().t_c, 1e-8));
  EXPECT_THROW(AnalyticAverage(0.0), std::invalid_argument);
  EXPECT_THROW(AnalyticAverage(std::nan("")), std::invalid_argument);
}

// Eq. 46 is a mean distance, not a mean square: one point 1 m off (an estimate after an echo)
// pulls the least-squares fit, much less the numerical one.
TEST(SimilarityTransform, TheNumericalFitMinimizesTheMeanDistanceAndResistsAnOutlier) {
  std::mt19937_64 rng(5);
  std::vector<PointPair> points = spread_points(noisy_track(rng, 0.01), 0.5, 12);
  points[3].global_m += Eigen::Vector2d(1.0, 0.0);
  const TransformFit fit = numerical_similarity(points);
  ASSERT_EQ(fit.failure, TransformFailure::kNone);
  const TransformFit least_squares = numerical_similarity(points, {1, 1e-10, 1e-6});  // the start alone
  EXPECT_GT(fit.iterations, 1);
  EXPECT_TRUE(fit.converged);
  EXPECT_LE(fit.mean_error_m, least_squares.mean_error_m);
  EXPECT_LT(beacon_error_m(*fit.transform), 0.5 * beacon_error_m(*least_squares.transform));
}

TEST(SimilarityTransform, TheNumericalFitRefusesTooFewOrBadPoints) {
  EXPECT_EQ(numerical_similarity({pair_at({1.0, 1.0})}).failure, TransformFailure::kTooFewPoints);
  EXPECT_EQ(numerical_similarity({pair_at({1.0, 1.0}), pair_at({1.0, 1.0})}).failure, TransformFailure::kSingular);
  PointPair inf = pair_at({5.0, 1.0});
  inf.local_m.y() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(numerical_similarity({pair_at({1.0, 1.0}), inf}).failure, TransformFailure::kNonFinite);
}

}  // namespace
}  // namespace beaconloc::scan
