// Evaluation: the papers' metrics on tracks whose errors are known, files round-trip, plots.
#include "evaluation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "beaconloc/core/csv_reader.hpp"
#include "svg_plot.hpp"

namespace beaconloc {
namespace {

std::vector<EstimateRow> shifted(const TruthTrack& truth, const Pose2& offset, const Cov3& cov) {
  std::vector<EstimateRow> rows;
  for (const auto& [stamp, s] : truth.samples()) {
    EstimateRow r{"r", {stamp, s.pose_map_base + offset, cov, PoseStatus::kOk}, "test"};
    rows.push_back(r);
  }
  return rows;
}

TruthTrack circle_track(bool with_yaw) {
  TruthTrack t;
  for (int k = 0; k < 100; ++k) {
    const double a = 0.05 * k;
    t.add(k * 10'000'000LL, {std::cos(a), std::sin(a), wrap_angle_rad(a + M_PI / 2)}, with_yaw);
  }
  return t;
}

TEST(Evaluation, KnownOffsetsGiveKnownMetrics) {
  const TruthTrack truth = circle_track(true);
  const auto rows = shifted(truth, {0.03, 0.04, 2.0 * M_PI / 180.0}, Cov3::Identity());
  const Metrics m = evaluate(truth, rows);
  EXPECT_EQ(m.samples, 100u);
  EXPECT_NEAR(m.position_rms_m, 0.05, 1e-12);
  EXPECT_NEAR(m.position_max_m, 0.05, 1e-12);
  EXPECT_NEAR(*m.heading_rms_deg, 2.0, 1e-9);
  // Eq. 35: every significant point moves by the translation plus its rotation by 2 degrees.
  EXPECT_GT(*m.significant_points_mean_m, 0.05 - 0.32 * 0.035);
  EXPECT_LT(*m.significant_points_mean_m, 0.05 + 0.32 * 0.035);
  EXPECT_EQ(m.nees_dof, 3);
}

TEST(Evaluation, SignificantPointsWithoutTranslationAreTheRotationOfThePoints) {
  const TruthTrack truth = circle_track(true);
  const double dphi = 5.0 * M_PI / 180.0;
  const Metrics m = evaluate(truth, shifted(truth, {0.0, 0.0, dphi}, Cov3::Identity()));
  double sum_sq = 0;
  for (const auto& p : significant_points_base_m())
    sum_sq += std::pow(2.0 * std::sin(dphi / 2.0) * p.norm(), 2);
  EXPECT_NEAR(*m.significant_points_mean_m, std::sqrt(sum_sq / 5.0), 1e-12);
}

TEST(Evaluation, NeesBandTellsHonestFromOverconfidentCovariances) {
  const TruthTrack truth = circle_track(true);
  const Pose2 error(0.01, -0.01, 0.01);  // NEES = 3 with unit-variance 0.01^2 covariance: in the band
  EXPECT_NEAR(evaluate(truth, shifted(truth, error, 1e-4 * Cov3::Identity())).nees_in_band_fraction, 1.0,
              1e-12);
  EXPECT_NEAR(evaluate(truth, shifted(truth, error, 1e-6 * Cov3::Identity())).nees_in_band_fraction, 0.0,
              1e-12);
}

// Seed 002's path error: its RMS keeps the mean its standard deviation takes out (rms^2 = std^2 +
// mean^2), and estimates before score_from_ns are counted, not scored.
TEST(Evaluation, PathErrorRmsKeepsItsMeanAndEstimatesBeforeScoringAreCounted) {
  const TruthTrack truth = circle_track(true);
  std::vector<EstimateRow> rows = shifted(truth, {0.0, 0.0, 0.0}, 1e-4 * Cov3::Identity());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    // 2 cm to the left of the path, +-1 cm alternating: mean 0.02 m, std 0.01 m across the path
    const double yaw = rows[i].estimate.pose_map_base.z(), across = 0.02 + (i % 2 ? 0.01 : -0.01);
    rows[i].estimate.pose_map_base.x() -= across * std::sin(yaw);
    rows[i].estimate.pose_map_base.y() += across * std::cos(yaw);
  }
  const Metrics all = evaluate(truth, rows);
  ASSERT_TRUE(all.path_error_std_m && all.path_error_rms_m);
  EXPECT_NEAR(*all.path_error_rms_m * *all.path_error_rms_m,
              *all.path_error_std_m * *all.path_error_std_m + 0.02 * 0.02, 1e-6);
  EXPECT_NEAR(*all.path_error_std_m, 0.01, 2e-3);
  EXPECT_EQ(all.samples_before_scoring, 0u);
  EvaluationOptions later;
  later.score_from_ns = rows[10].estimate.stamp_ns;
  const Metrics from_tenth = evaluate(truth, rows, later);
  EXPECT_EQ(from_tenth.samples_before_scoring, 10u);
  EXPECT_EQ(from_tenth.samples, all.samples - 10);
}

TEST(Evaluation, TruthWithoutHeadingScoresPositionOnlyAndInterpolates) {
  TruthTrack truth;
  truth.add(0, {0.0, 0.0, 0.0}, false);
  truth.add(200'000'000, {2.0, 0.0, 0.0}, false);
  std::vector<EstimateRow> rows = {
      {"r", {100'000'000, {1.0, 0.1, 3.0}, Cov3::Identity(), PoseStatus::kOk}, "t"},
      {"r", {900'000'000, {1.0, 0.0, 0.0}, Cov3::Identity(), PoseStatus::kOk}, "t"}};
  const Metrics m = evaluate(truth, rows);
  EXPECT_EQ(m.samples, 1u);
  EXPECT_EQ(m.samples_without_truth, 1u);  // past the end of the truth
  EXPECT_NEAR(m.position_rms_m, 0.1, 1e-12);
  EXPECT_FALSE(m.heading_rms_deg);
  EXPECT_FALSE(m.significant_points_mean_m);
  EXPECT_EQ(m.nees_dof, 2);
  EvaluationOptions tight;
  tight.max_truth_gap_ns = 100'000'000;  // the 200 ms gap is too long to interpolate over
  EXPECT_EQ(evaluate(truth, rows, tight).samples, 0u);
}

TEST(Evaluation, FilesRoundTripAndPlotsAreWritten) {
  const std::string dir = ::testing::TempDir() + "/evaluation_files";
  std::filesystem::create_directories(dir);
  const TruthTrack truth = circle_track(true);
  const auto rows = shifted(truth, {0.01, 0.0, 0.0}, 2e-4 * Cov3::Identity());
  write_estimates_csv(dir + "/estimate.csv", rows);
  const auto back = load_estimates_csv(dir + "/estimate.csv");
  ASSERT_EQ(back.size(), rows.size());
  EXPECT_TRUE(back[7].estimate.pose_map_base.isApprox(rows[7].estimate.pose_map_base, 1e-10));
  EXPECT_TRUE(back[7].estimate.covariance.isApprox(rows[7].estimate.covariance, 1e-10));
  write_metrics_json(dir + "/metrics.json", evaluate(truth, back), "test", "unit");
  std::ifstream json(dir + "/metrics.json");
  const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  for (const char* key : {"position_rms_m", "position_max_m", "position_mean_m", "heading_rms_deg",
                          "significant_points_mean_m", "nees_in_band_fraction", "samples"}) {
    EXPECT_NE(text.find(std::string("\"") + key + "\""), std::string::npos) << key;
  }
  write_trajectory_svg(dir + "/t.svg", "t", truth, rows, BeaconMap({{1, {0, 0, 2}, 0}}));
  write_error_svg(dir + "/e.svg", "e", error_series(truth, rows));
  EXPECT_GT(std::filesystem::file_size(dir + "/t.svg"), 1000u);
  EXPECT_GT(std::filesystem::file_size(dir + "/e.svg"), 1000u);
  std::ofstream(dir + "/bad.csv") << "stamp_ns,x_m,y_m,yaw_rad\n1,2,three,4\n";
  try {
    load_truth_csv(dir + "/bad.csv");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2"), std::string::npos) << e.what();
  }
}

// The truth and estimate CSVs: every number decimal and within its column's range, named with
// the file, line and column; a byte order mark before the header is an encoding mark.
TEST(Evaluation, EveryNumberOfTheCsvFilesIsCheckedNamingItsColumn) {
  const std::string dir = ::testing::TempDir() + "/evaluation_numbers";
  std::filesystem::create_directories(dir);
  const auto truth_error = [&](const std::string& text) {
    std::ofstream(dir + "/truth.csv") << text;
    try {
      load_truth_csv(dir + "/truth.csv");
    } catch (const CsvError& e) {
      const std::string what = e.what();
      return what.substr(what.find("truth.csv"));
    }
    return std::string();
  };
  const std::string header = "stamp_ns,x_m,y_m,yaw_rad\n";
  EXPECT_EQ(truth_error(header + "1,0x1p1,0,0\n"), "truth.csv:2: x_m '0x1p1' is not a decimal number");
  EXPECT_EQ(truth_error(header + "1,1e300,0,0\n"), "truth.csv:2: x_m 1e+300 is outside [-1e+06, 1e+06]");
  EXPECT_EQ(truth_error(header + "1,0,1e400,0\n"), "truth.csv:2: y_m '1e400' is out of range");
  EXPECT_EQ(truth_error(header + "1,0,0,1e7\n"), "truth.csv:2: yaw_rad 1e+07 is outside [-1e+06, 1e+06]");
  EXPECT_EQ(truth_error(header + "1.5,0,0,0\n"),
            "truth.csv:2: stamp_ns '1.5' is not a decimal number (a stamp in ns)");
  EXPECT_EQ(truth_error(header + "-1,0,0,0\n"),
            "truth.csv:2: stamp_ns -1 is outside [0, 9223372036854775807] (a stamp in ns)");
  EXPECT_EQ(truth_error(header + "0x10,0,0,0\n"),
            "truth.csv:2: stamp_ns '0x10' is not a decimal number (a stamp in ns)");
  EXPECT_EQ(truth_error("\xEF\xBB\xBF" + header + "1,0.5,0,0\n"), "");
  EXPECT_EQ(load_truth_csv(dir + "/truth.csv").samples().size(), 1u);
  EXPECT_EQ(truth_error("stamp_ns,x_m,y_m,yaw_rad,x_m\n1,0,0,0,1\n"),
            "truth.csv:1: header names column 'x_m' twice");
  std::ofstream(dir + "/estimate.csv") << "\xEF\xBB\xBFrobot_id,stamp_ns,x_m,y_m,yaw_rad,cov_00,cov_01,cov_"
                                          "02,cov_10,cov_11,cov_12,cov_20,cov_21,"
                                          "cov_22,status,estimator\nr,1,0,0,0,1,0,0,0,1,0,0,0,inf,ok,e\n";
  try {
    load_estimates_csv(dir + "/estimate.csv");
    FAIL() << "an infinite covariance loaded";
  } catch (const CsvError& e) {
    EXPECT_NE(std::string(e.what()).find("estimate.csv:2: cov_22 'inf' is not a decimal number"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace beaconloc
