// Every estimator the product registers, on the scenario it names as its reference (its paper's
// setup, EstimatorRegistry::reference_scenario), through the offline stack (decoder and localizer
// cores as the participants run them), scored against the simulator's truth. A new estimator
// folder is run here with no edit; its own accuracy tests (<name>/accuracy/) hold it to its paper.
//
// What every estimator must do on its own paper's setup:
//  - produce poses (a run that produced nothing is a failure, never a score), scored on truth,
//    and never one the localizer must throw away (non-finite, broken covariance);
//  - localize: a position RMS below 0.5 m. Every paper we implement reports 1-25 cm on its setup;
//    0.5 m is the line past which a robot in a room does not know which doorway it is at;
//  - be a function of its inputs: the same seed run twice gives the same figures to the last bit
//    (no clock read, no state shared between instances).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "offline_run.hpp"
#include "shipped_estimators.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc {
namespace {

constexpr double kLocalizedRmsM = 0.5;

class EveryEstimator : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryEstimator, LocalizesOnItsReferenceScenarioAndRepeatsItself) {
  const std::string name = GetParam();
  const std::string file = EstimatorRegistry::instance().reference_scenario(name);
  ASSERT_FALSE(file.empty()) << name << " names no reference scenario (BEACONLOC_REGISTER_ESTIMATOR)";
  const sim::Scenario scenario =
      sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/" + file);
  const OfflineRunResult first = run_scenario_offline(scenario, 1, name, {}, 5.0);
  const OfflineRunResult again = run_scenario_offline(scenario, 1, name, {}, 5.0);
  std::printf("%s on %s, seed 1: %zu poses, %zu scored, position RMS %.4f m, max %.4f m, NEES in band %.0f %%\n",
              name.c_str(), file.c_str(), first.poses, first.metrics.samples, first.metrics.position_rms_m,
              first.metrics.position_max_m, 100.0 * first.metrics.nees_in_band_fraction);
  ASSERT_GT(first.poses, 0u) << name << ": no pose";
  ASSERT_GT(first.metrics.samples, 0u) << name << ": no pose scored against truth";
  ASSERT_TRUE(std::isfinite(first.metrics.position_rms_m));
  EXPECT_EQ(first.rejections.rejected("localizer.estimate.unusable"), 0u) << name;
  EXPECT_LT(first.metrics.position_rms_m, kLocalizedRmsM) << name;
  EXPECT_EQ(first.poses, again.poses) << name;
  EXPECT_EQ(first.metrics.position_rms_m, again.metrics.position_rms_m) << name;
  EXPECT_EQ(first.metrics.position_max_m, again.metrics.position_max_m) << name;
  EXPECT_EQ(first.rejections.rejected_by_reason(), again.rejections.rejected_by_reason()) << name;
}

INSTANTIATE_TEST_SUITE_P(Registered, EveryEstimator, ::testing::ValuesIn(shipped_estimators()),
                         [](const ::testing::TestParamInfo<std::string>& param) { return param.param; });

}  // namespace
}  // namespace beaconloc
