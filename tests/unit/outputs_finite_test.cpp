// No output carries a non-finite number: the writers of estimates and metrics refuse one whole
// (every reader refuses such a pose at its door, so one here is a bug upstream), and a run that
// scored nothing writes no figure at all (issue 23).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "evaluation.hpp"

namespace beaconloc {
namespace {

class OutputsFinite : public ::testing::Test {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/beaconloc-outputs-XXXXXX";
    ASSERT_NE(::mkdtemp(dir), nullptr);
    dir_ = dir;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  static std::string read(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  std::string dir_;
};

std::vector<EstimateRow> rows_with(double x) {
  std::vector<EstimateRow> rows(3, EstimateRow{"r", PoseEstimate{}, "range_ekf"});
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i].estimate.stamp_ns = static_cast<StampNs>(i + 1);
  rows[1].estimate.pose_map_base.x() = x;
  return rows;
}

TEST_F(OutputsFinite, AnEstimateCsvIsNeverWrittenWithANonFiniteNumber) {
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    const std::string path = dir_ + "/estimate.csv";
    EXPECT_THROW(write_estimates_csv(path, rows_with(bad)), std::invalid_argument);
    EXPECT_FALSE(std::filesystem::exists(path));
  }
  auto rows = rows_with(1.0);
  rows[2].estimate.covariance(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_estimates_csv(dir_ + "/e.csv", rows), std::invalid_argument);
  write_estimates_csv(dir_ + "/good.csv", rows_with(1.0));
  EXPECT_EQ(load_estimates_csv(dir_ + "/good.csv").size(), 3u);
}

TEST_F(OutputsFinite, EvaluationRefusesANonFiniteEstimate) {
  TruthTrack truth;
  for (StampNs t = 0; t < 5; ++t) truth.add(t, Pose2::Zero());
  EXPECT_THROW(evaluate(truth, rows_with(std::numeric_limits<double>::quiet_NaN())), std::invalid_argument);
  // Finite but beyond any site (publishable()): its squared error overflowed the RMS to inf.
  EXPECT_THROW(evaluate(truth, rows_with(1e200)), std::invalid_argument);
  EXPECT_THROW(write_estimates_csv(dir_ + "/far.csv", rows_with(1e200)), std::invalid_argument);
  EXPECT_EQ(evaluate(truth, rows_with(0.5)).samples, 3u);
}

TEST_F(OutputsFinite, MetricsJsonHasNoFigureWithoutSamplesAndNeverANonFiniteOne) {
  Metrics none;
  none.samples_without_truth = 7;
  write_metrics_json(dir_ + "/none.json", none, "range_ekf", "test");
  const std::string json = read(dir_ + "/none.json");
  for (const char* key : {"position_rms_m", "position_mean_m", "position_max_m", "nees_in_band_fraction"}) {
    EXPECT_NE(json.find(std::string("\"") + key + "\": null"), std::string::npos) << key << "\n" << json;
  }
  Metrics bad;
  bad.samples = 3;
  bad.position_rms_m = std::numeric_limits<double>::infinity();
  EXPECT_THROW(write_metrics_json(dir_ + "/bad.json", bad, "range_ekf", "test"), std::runtime_error);
  bad.position_rms_m = 0.1;
  bad.heading_rms_deg = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_metrics_json(dir_ + "/bad.json", bad, "range_ekf", "test"), std::runtime_error);
}

}  // namespace
}  // namespace beaconloc
