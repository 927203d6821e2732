// The estimators' parameters (--param NAME=VALUE): every estimator reads them through one
// reader that refuses, at creation, a name it does not know, a value outside its range, a count
// that is not whole (1e300 included: checked before it is converted) and a flag that is not 0 or
// 1, each with a message naming the parameter, the value and the range or the known names.
#include "beaconloc/core/estimator_parameters.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "beaconloc/core/estimator_registry.hpp"
#include "localizer_core.hpp"
#include "shipped_estimators.hpp"

namespace beaconloc {
namespace {

using Reason = EstimatorParameterError::Reason;

// A configuration every registered estimator can be created with (ring receivers for duhl and
// uhl_last2, one receiver and a map for ukf_lrf, one receiver at the centre for kleeman_iekf,
// two for two_receiver_ekf).
EstimatorConfig config_for(const std::string& estimator, std::map<std::string, double> parameters) {
  EstimatorConfig c;
  const bool one_at_centre = estimator.rfind("ukf_lrf", 0) == 0 || estimator == "kleeman_iekf" || estimator == "scan";
  c.receivers = ReceiverArray::on_circle(one_at_centre ? 0.0 : 0.19, one_at_centre ? 1 : 3);
  if (estimator == "two_receiver_ekf") c.receivers = ReceiverArray::on_circle(0.133, 2);  // front and rear
  c.occupancy_grid = std::make_shared<const OccupancyGrid>(Eigen::Vector2d::Zero(), 0.1, 40, 40);
  c.parameters = std::move(parameters);
  return c;
}

// The refusal of creating estimator with these parameters; fails the test if none.
EstimatorParameterError refusal(const std::string& estimator, std::map<std::string, double> parameters) {
  try {
    EstimatorRegistry::instance().create(estimator, config_for(estimator, std::move(parameters)));
  } catch (const EstimatorParameterError& e) {
    return e;
  }
  ADD_FAILURE() << estimator << ": no EstimatorParameterError";
  return EstimatorParameterError(Reason::kUnknownName, "", "");
}

bool mentions(const std::exception& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

TEST(EstimatorParameters, EveryEstimatorStartsWithItsDefaults) {
  for (const auto& name : shipped_estimators()) {
    EXPECT_NO_THROW(EstimatorRegistry::instance().create(name, config_for(name, {}))) << name;
  }
}

TEST(EstimatorParameters, AnUnknownNameIsRefusedListingTheKnownOnes) {
  for (const auto& name : shipped_estimators()) {
    const EstimatorParameterError e = refusal(name, {{"nis_gat", 3.0}});
    EXPECT_EQ(e.reason(), Reason::kUnknownName) << name;
    EXPECT_EQ(e.parameter(), "nis_gat") << name;
    EXPECT_TRUE(mentions(e, name + ": unknown parameter 'nis_gat' (known: ")) << e.what();
  }
  EXPECT_TRUE(mentions(refusal("range_ekf", {{"typo", 1.0}}), "nis_gate, init_window_s"));
  EXPECT_TRUE(mentions(refusal("duhl", {{"typo", 1.0}}), "observation_nis_gate"));
  EXPECT_TRUE(mentions(refusal("ukf_lrf", {{"typo", 1.0}}), "ut_alpha"));
  // A parameter of another estimator is unknown to this one.
  EXPECT_EQ(refusal("uhl_last2", {{"observation_nis_gate", 16.0}}).reason(), Reason::kUnknownName);
  EXPECT_EQ(refusal("range_ekf", {{"ut_alpha", 0.5}}).reason(), Reason::kUnknownName);
  // The spread test that item 9 replaced is gone, not silently ignored.
  EXPECT_EQ(refusal("range_ekf", {{"init_min_beacon_spread_m", 0.2}}).reason(), Reason::kUnknownName);
}

TEST(EstimatorParameters, ValuesOutsideTheirRangeAreRefusedNamingValueAndRange) {
  struct Case {
    const char* estimator;
    const char* parameter;
    double value;
    const char* range;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Case& c : std::vector<Case>{
           {"range_ekf", "init_window_s", -1.0, "(0, 60]"},
           {"range_ekf", "max_odometry_gap_s", -1.0, "(0, 10]"},
           {"range_ekf", "nis_gate", -1.0, "(0, 1000]"},
           {"range_ekf", "nis_gate", 0.0, "(0, 1000]"},  // an open end
           {"range_ekf", "nis_gate", nan, "(0, 1000]"},
           {"range_ekf", "init_max_yaw_sigma_rad", 4.0, "(0, 3.14159"},
           {"range_ekf", "init_outlier_gate_sigma", -0.5, "[0, 100]"},
           {"duhl", "max_odometry_gap_s", -1.0, "(0, 10]"},
           {"duhl", "observation_nis_gate", 2000.0, "(0, 1000]"},
           {"duhl", "discard_variance_m2", 0.0, "(0, 1]"},
           {"uhl_last2", "uhl_collinear_threshold_m", -0.3, "(0, 10]"},
           {"ukf_lrf", "ut_alpha", 0.0, "(0, 1]"},
           {"ukf_lrf", "ut_alpha", 1.5, "(0, 1]"},
           {"ukf_lrf_laser_only", "ut_kappa", -10.0, "(-4, 100]"},
           {"ukf_lrf_beacons_only", "beacon_sigma_m", 0.0, "(0, 10]"},
           {"ukf_lrf_beacons_only", "alpha2", -0.01, "[0, 1]"},
       }) {
    const EstimatorParameterError e = refusal(c.estimator, {{c.parameter, c.value}});
    EXPECT_EQ(e.reason(), Reason::kOutOfRange) << c.estimator << " " << c.parameter;
    EXPECT_EQ(e.parameter(), c.parameter);
    EXPECT_TRUE(mentions(e, std::string(c.estimator) + ": parameter " + c.parameter + "=")) << e.what();
    EXPECT_TRUE(mentions(e, c.range)) << e.what();
  }
  EXPECT_TRUE(mentions(refusal("range_ekf", {{"nis_gate", -1.0}}), "nis_gate=-1 is outside (0, 1000]"));
  // The ends that belong to the range are taken.
  EXPECT_NO_THROW(
      EstimatorRegistry::instance().create("ukf_lrf", config_for("ukf_lrf", {{"ut_alpha", 1.0}})));
  EXPECT_NO_THROW(
      EstimatorRegistry::instance().create("range_ekf", config_for("range_ekf", {{"nis_gate", 1000.0}})));
}

TEST(EstimatorParameters, ACountMustBeAWholeNumberInItsRangeAndIsCheckedBeforeItIsConverted) {
  const EstimatorParameterError half = refusal("range_ekf", {{"init_min_beacons", 2.5}});
  EXPECT_EQ(half.reason(), Reason::kNotWhole);
  EXPECT_TRUE(mentions(half, "init_min_beacons=2.5 is not a whole number (a count in [1, 100])"))
      << half.what();
  // 1e300 does not fit an int: converting it would be undefined behaviour. Refused as out of range.
  for (double huge : {1e300, -1e300, 2147483648.0, 1e10}) {
    const EstimatorParameterError e = refusal("range_ekf", {{"init_min_beacons", huge}});
    EXPECT_EQ(e.reason(), Reason::kOutOfRange) << huge;
    EXPECT_TRUE(mentions(e, "is outside [1, 100]")) << e.what();
  }
  EXPECT_TRUE(mentions(refusal("range_ekf", {{"init_min_beacons", 1e300}}), "init_min_beacons=1e+300"));
  EXPECT_EQ(refusal("range_ekf", {{"init_min_ranges", 3.0}}).reason(),
            Reason::kOutOfRange);  // the solver needs 4
  EXPECT_EQ(refusal("range_ekf", {{"reinitialize_after_gated", 0.0}}).reason(), Reason::kOutOfRange);
  EXPECT_EQ(refusal("ukf_lrf", {{"max_beams", 0.0}}).reason(), Reason::kOutOfRange);
  EXPECT_EQ(refusal("ukf_lrf", {{"max_beams", 19.5}}).reason(), Reason::kNotWhole);
  // A count bounded by another: no more gated ranges than the window holds.
  EXPECT_EQ(
      refusal("range_ekf", {{"divergence_window_ranges", 10.0}, {"divergence_gated_ranges", 11.0}}).reason(),
      Reason::kOutOfRange);
  EXPECT_NO_THROW(EstimatorRegistry::instance().create(
      "range_ekf",
      config_for("range_ekf", {{"divergence_window_ranges", 10.0}, {"divergence_gated_ranges", 10.0}})));
  // duhl: 0 switches its re-initialization off.
  EXPECT_NO_THROW(
      EstimatorRegistry::instance().create("duhl", config_for("duhl", {{"reinitialize_after_gated", 0.0}})));
}

TEST(EstimatorParameters, AFlagIsZeroOrOne) {
  const EstimatorParameterError e = refusal("duhl", {{"observation_covariance_as_printed", 0.5}});
  EXPECT_EQ(e.reason(), Reason::kNotAFlag);
  EXPECT_TRUE(mentions(e, "observation_covariance_as_printed=0.5 is not a flag (0 or 1)")) << e.what();
  EXPECT_NO_THROW(EstimatorRegistry::instance().create(
      "duhl", config_for("duhl", {{"observation_covariance_as_printed", 1.0}})));
}

TEST(EstimatorParameters, TheReaderReadsEachKindAndListsWhatItWasNotAskedFor) {
  EstimatorConfig c;
  c.parameters = {{"gain", 0.5}, {"count", 7.0}, {"on", 1.0}, {"stray", 2.0}, {"other", 3.0}};
  ParameterReader in(c, "test");
  EXPECT_EQ(in.real("gain", 0.9, ParameterRange::open(0.0, 1.0)), 0.5);
  EXPECT_EQ(in.real("absent", 0.25, ParameterRange::closed(0.0, 1.0)), 0.25);  // the default
  EXPECT_EQ(in.count("count", 1, 1, 10), 7);
  EXPECT_TRUE(in.flag("on", false));
  EXPECT_EQ(in.known(), (std::vector<std::string>{"gain", "absent", "count", "on"}));
  try {
    in.finish();
    FAIL() << "expected the unread names refused";
  } catch (const EstimatorParameterError& e) {
    EXPECT_EQ(e.reason(), Reason::kUnknownName);
    EXPECT_EQ(std::string(e.what()),
              "test: unknown parameter 'other', 'stray' (known: gain, absent, count, on)");
  }
  // A default outside its own range is the programmer's error, not the user's.
  EXPECT_THROW(in.real("bad_default", 2.0, ParameterRange::closed(0.0, 1.0)), std::logic_error);
  EXPECT_EQ(ParameterRange::above(0.0, 1.0).to_string(), "(0, 1]");
  EXPECT_EQ(ParameterRange::open(-0.5, 2.0).to_string(), "(-0.5, 2)");
  EXPECT_FALSE(ParameterRange::closed(0.0, 1.0).contains(std::nan("")));
}

TEST(EstimatorParameters, AParameterGivenTwiceIsRefused) {
  EXPECT_EQ(parse_estimator_parameters({"nis_gate=3", "init_window_s=2"}, "--param").size(), 2u);
  try {
    parse_estimator_parameters({"nis_gate=3", "nis_gate=4"}, "--param");
    FAIL() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(mentions(e, "nis_gate is given twice")) << e.what();
  }
}

TEST(EstimatorParameters, TheLocalizerRefusesABadParameterAtStart) {
  EstimatorConfig c;
  c.receivers = ReceiverArray::on_circle(0.19, 3);
  c.parameters = {{"typo", 1.0}};
  EXPECT_THROW(LocalizerCore("range_ekf", c), EstimatorParameterError);
  c.parameters = {{"init_min_beacons", 1e300}};
  EXPECT_THROW(LocalizerCore("range_ekf", c), EstimatorParameterError);
}

}  // namespace
}  // namespace beaconloc
