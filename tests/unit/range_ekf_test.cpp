// range_ekf on the simulated seed-000 setup, without DDS: accuracy against the simulator's truth,
// an honest covariance, a global start with no prior, and typed rejections of bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "beaconloc/core/estimator_registry.hpp"
#include "offline_pipeline.hpp"
#include "sim/scenario.hpp"

namespace beaconloc {
namespace {

TEST(RangeEkf, IsRegisteredByNameAndUnknownNamesAreRefused) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  EXPECT_EQ(EstimatorRegistry::instance().create("range_ekf", config)->name(), "range_ekf");
  try {
    EstimatorRegistry::instance().create("no_such_filter", config);
    FAIL() << "expected UnknownEstimator";
  } catch (const UnknownEstimator& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_filter"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("range_ekf"), std::string::npos);
  }
}

TEST(RangeEkf, TracksTheDefaultScenarioOverTenSeeds) {
  double worst_rms = 0.0, sum_rms = 0.0, sum_heading = 0.0, sum_nees = 0.0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const auto run = testing::run_offline(sim::default_scenario(), seed, 60.0);
    ASSERT_GT(run.error.samples(), 5000u) << "seed " << seed;
    worst_rms = std::max(worst_rms, run.error.position_rms_m());
    sum_rms += run.error.position_rms_m();
    sum_heading += run.error.heading_rms_deg();
    sum_nees += run.nees_in_band_fraction();
    EXPECT_EQ(run.localizer_counts.rejected("range.gated_nis") * 100 < run.localizer_counts.accepted(), true)
        << "more than 1 % of good ranges gated, seed " << seed;
  }
  std::printf(
      "range_ekf, default scenario, 10 seeds x 60 s: mean position RMS %.4f m (worst %.4f), "
      "mean heading RMS %.2f deg, mean NEES-in-95%%-band %.2f\n",
      sum_rms / 10, worst_rms, sum_heading / 10, sum_nees / 10);
  EXPECT_LT(worst_rms, 0.05);
  EXPECT_LT(sum_heading / 10, 3.0);
  EXPECT_GE(sum_nees / 10, 0.80) << "the covariance is not honest";
}

TEST(RangeEkf, LocalizesFromBeaconsAloneWhenStartedLate) {
  // No prior pose: the localizer starts 5 s into the run, mid-path.
  const auto run = testing::run_offline(sim::default_scenario(), 4, 30.0, "range_ekf", 5.0);
  ASSERT_GT(run.poses, 0u);
  EXPECT_LT(run.first_pose_s, 5.0 + 2.0);  // a global fix within two seconds (1.2 s cycle)
  EXPECT_LT(run.error.position_rms_m(), 0.05);
}

TEST(RangeEkf, RefusesBadInputWithATypedReason) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  auto ekf = EstimatorRegistry::instance().create("range_ekf", config);
  ekf->set_beacon_map(BeaconMap({{1, {0.0, 0.0, 2.0}, 0}}));
  OdometrySample o;
  o.stamp_ns = 1'000'000'000;
  o.wheel_base_m = 0.33;
  EXPECT_TRUE(ekf->predict(o).accepted);
  EXPECT_EQ(ekf->predict(o).rejection, "duplicate_odometry");
  o.stamp_ns -= 10'000'000;
  EXPECT_EQ(ekf->predict(o).rejection, "out_of_order_odometry");
  o.stamp_ns = 2'000'000'000;
  EXPECT_EQ(ekf->predict(o).rejection, "odometry_gap");
  o.stamp_ns += 10'000'000;
  o.wheel_velocity_left_mps = std::nan("");
  EXPECT_EQ(ekf->predict(o).rejection, "non_finite_odometry");
  o.wheel_velocity_left_mps = 0.0;
  o.wheel_base_m = 0.0;
  EXPECT_EQ(ekf->predict(o).rejection, "invalid_wheel_base");
  o.wheel_base_m = 0.33;
  o.wheel_velocity_covariance(1, 1) = -1e-6;
  EXPECT_EQ(ekf->predict(o).rejection, "invalid_odometry_covariance");
  o.wheel_velocity_covariance(1, 1) = 0.0;

  RangeMeasurement r;
  r.stamp_ns = 2'000'000'000;
  r.beacon_id = 1;
  r.receiver_id = 0;
  r.range_m = 2.1;
  r.variance_m2 = 1e-4;
  EXPECT_TRUE(ekf->update(r).accepted);
  r.beacon_id = 7;
  EXPECT_EQ(ekf->update(r).rejection, "unknown_beacon");
  r.beacon_id = kBeaconUnidentified;
  EXPECT_EQ(ekf->update(r).rejection, "unassociated_range");
  r.beacon_id = 1;
  r.receiver_id = 3;
  EXPECT_EQ(ekf->update(r).rejection, "unknown_receiver");
  r.receiver_id = 0;
  r.range_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ekf->update(r).rejection, "non_finite_range");
  r.range_m = 2.1;
  r.stamp_ns = 1'000'000'000;
  EXPECT_EQ(ekf->update(r).rejection, "stale_range");
  EXPECT_FALSE(ekf->estimate());  // one beacon cannot give a pose
  EXPECT_EQ(ekf->status(), PoseStatus::kInitializing);
}

TEST(RangeEkf, DegradesWithoutRangesAndRecoversWhenTheyReturn) {
  testing::OfflineStack stack(sim::default_scenario());
  PoseStatus at_8s = PoseStatus::kInitializing, at_20s = PoseStatus::kInitializing;
  for (const auto& e : testing::simulate(sim::default_scenario(), 2, 20.0)) {
    const double t = ns_to_s(e.stamp_ns);
    const bool silenced = e.kind == SourceEvent::Kind::kTof && t > 5.0 && t < 8.0;
    if (silenced) continue;  // the beacons fall silent for 3 s
    const auto pose = stack.feed("r", e);
    if (pose && std::abs(t - 7.9) < 0.005) at_8s = pose->estimate.status;
    if (pose) at_20s = pose->estimate.status;
  }
  EXPECT_EQ(at_8s, PoseStatus::kDegraded);
  EXPECT_EQ(at_20s, PoseStatus::kOk);
}

}  // namespace
}  // namespace beaconloc
