// Typed rejections (issue 14): one enumeration with stable, distinct snake_case names, and the
// same bad input refused for the same reason by every registered estimator (new ones included:
// the test walks the registry).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/rejection.hpp"
#include "shipped_estimators.hpp"
#include "standing_odometry.hpp"

namespace beaconloc {
namespace {

TEST(Rejection, EveryReasonHasItsOwnSnakeCaseName) {
  std::set<std::string> names;
  for (int i = 0; i < kRejectionCount; ++i) {
    const std::string name = to_string(static_cast<Rejection>(i));
    EXPECT_NE(name, "unknown") << i;
    EXPECT_TRUE(names.insert(name).second) << "two reasons named " << name;
    for (char c : name) EXPECT_TRUE((c >= 'a' && c <= 'z') || c == '_') << name;
  }
}

TEST(Rejection, EveryFilterOutcomeHasItsReason) {
  for (FilterOutcome o : {FilterOutcome::kGated, FilterOutcome::kSingularInnovation, FilterOutcome::kNotPositiveDefinite,
                          FilterOutcome::kBoundNotMet, FilterOutcome::kNonFinite, FilterOutcome::kSizeMismatch,
                          FilterOutcome::kStaleSigmaPoints, FilterOutcome::kEveryComponentGated}) {
    EXPECT_STREQ(to_string(o), to_string(*rejection_for(o)));
  }
  EXPECT_EQ(rejection_for(FilterOutcome::kGated), Rejection::kGatedNis);
  EXPECT_EQ(rejection_for(FilterOutcome::kApplied), std::nullopt);
}

const BeaconMap kMap({{1, {0.0, 0.0, 2.5}, 0}, {2, {3.0, 0.0, 2.5}, 0}, {3, {1.5, 2.0, 2.5}, 0}});

// An estimator as the localizer makes it, whichever receivers and map it needs: three receivers
// on a circle first (seed 000), else two, front and rear (seed 004), else one receiver with an
// occupancy grid and a placed pose (seed 001); all carry an initial pose, which some ignore.
std::unique_ptr<Estimator> make(const std::string& name) {
  EstimatorConfig ring;
  ring.receivers = ReceiverArray::on_circle(0.19, 3);
  ring.initial_pose = Pose2(1.0, 1.0, 0.0);
  try {
    return EstimatorRegistry::instance().create(name, ring);
  } catch (const std::invalid_argument&) {
  }
  EstimatorConfig pair = ring;  // seed 004: front and rear
  pair.receivers.receivers_base_m = {{0.133, 0.0}, {-0.133, 0.0}};
  try {
    return EstimatorRegistry::instance().create(name, pair);
  } catch (const std::invalid_argument&) {
  }
  EstimatorConfig single = ring;
  single.receivers.receivers_base_m = {{0.0, 0.0}};
  auto grid = std::make_shared<OccupancyGrid>(Eigen::Vector2d(-1.0, -1.0), 0.1, 60, 50);
  grid->fill_border();
  single.occupancy_grid = grid;
  return EstimatorRegistry::instance().create(name, single);
}

OdometrySample odometry(StampNs stamp_ns) { return standing_odometry(stamp_ns); }

TEST(Rejection, TheSameBadRangeGetsTheSameReasonFromEveryEstimator) {
  ASSERT_GE(shipped_estimators().size(), 5u);
  for (const std::string& name : shipped_estimators()) {
    auto e = make(name);
    e->set_beacon_map(kMap);
    ASSERT_TRUE(e->predict(odometry(1'000'000'000)).accepted) << name;
    RangeMeasurement r;
    r.stamp_ns = 1'000'000'000;
    r.beacon_id = 1;
    r.range_m = 2.0;
    r.variance_m2 = 1e-4;
    const auto reason = [&](RangeMeasurement bad) { return e->update(bad).rejection; };
    RangeMeasurement bad = r;
    bad.range_m = std::nan("");
    EXPECT_EQ(reason(bad), Rejection::kNonFiniteRange) << name;
    bad = r;
    bad.variance_m2 = std::numeric_limits<double>::infinity();
    EXPECT_EQ(reason(bad), Rejection::kNonFiniteRange) << name;
    bad = r;
    bad.range_m = -1.0;
    EXPECT_EQ(reason(bad), Rejection::kInvalidRange) << name;
    bad = r;
    bad.variance_m2 = 0.0;
    EXPECT_EQ(reason(bad), Rejection::kInvalidRange) << name;
    bad = r;
    bad.range_m = 1e9;
    EXPECT_EQ(reason(bad), Rejection::kImplausibleRange) << name;
    bad = r;
    bad.stamp_ns = -1;
    EXPECT_EQ(reason(bad), Rejection::kInvalidStamp) << name;
  }
}

TEST(Rejection, TheSameBadOdometryGetsTheSameReasonFromEveryEstimator) {
  for (const std::string& name : shipped_estimators()) {
    auto e = make(name);
    e->set_beacon_map(kMap);
    OdometrySample o = odometry(1'000'000'000);
    o.wheel_velocity_left_mps = std::nan("");
    EXPECT_EQ(e->predict(o).rejection, Rejection::kNonFiniteOdometry) << name;
    o = odometry(1'000'000'000);
    o.wheel_base_m = 0.0;
    EXPECT_EQ(e->predict(o).rejection, Rejection::kInvalidWheelBase) << name;
    o = odometry(-5);
    EXPECT_EQ(e->predict(o).rejection, Rejection::kInvalidStamp) << name;
    ASSERT_TRUE(e->predict(odometry(1'000'000'000)).accepted) << name;
    EXPECT_EQ(e->predict(odometry(1'000'000'000)).rejection, Rejection::kDuplicateOdometry) << name;
    EXPECT_EQ(e->predict(odometry(990'000'000)).rejection, Rejection::kOutOfOrderOdometry) << name;
  }
}

}  // namespace
}  // namespace beaconloc
