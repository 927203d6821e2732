#pragma once
// Accuracy of an estimated track against ground truth, with the papers' metrics: E_p and E_phi
// (seed 000 eq. 33-34) as RMS, mean and max; E_S over the significant points (eq. 35); and the
// share of steps whose NEES lies in the two-sided 95 % chi-square band (is the covariance honest?).
// DDS-free: used by `beaconloc run`, `beaconloc eval`, `demo`, `monitor` and the tests.
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/truth_track.hpp"

namespace beaconloc {

struct EstimateRow {
  std::string robot_id;
  PoseEstimate estimate;
  std::string estimator;
};

struct EvaluationOptions {
  // Truth is interpolated between samples at most this far apart (recordings give truth at
  // their own rate: 5 Hz for CMU Plaza 1).
  StampNs max_truth_gap_ns = 500'000'000;
  // Estimates before this stamp are not scored (e.g. a settling time); 0: all.
  StampNs score_from_ns = 0;
};

struct Metrics {
  std::size_t samples = 0;  // estimates scored (truth known at their stamp)
  std::size_t samples_without_truth = 0;
  std::size_t samples_before_scoring = 0;  // estimates before EvaluationOptions::score_from_ns
  double position_rms_m = 0.0;
  double position_mean_m = 0.0;
  double position_max_m = 0.0;
  std::optional<double> heading_rms_deg;            // where truth has heading
  std::optional<double> significant_points_mean_m;  // eq. 35, where truth has heading
  // Seed 002 Sec. 4's path error: the signed distance from the true path, left positive, taken
  // across the true heading at the pose's stamp (on a straight leg, the distance to the path the
  // paper measured; a lag along the path does not count). Where truth has heading.
  std::optional<double> path_error_std_m;
  std::optional<double> path_error_rms_m;  // with its mean (the figure a bound on the error is read against)
  std::optional<double> path_error_max_m;  // of its magnitude
  double nees_in_band_fraction = 0.0;
  int nees_dof = 3;  // 3 with heading in the truth, else 2 (position only)
};

// Seed 000, Section V: the significant points of the robot, in its frame.
const std::vector<Eigen::Vector2d>& significant_points_base_m();

Metrics evaluate(const TruthTrack& truth, const std::vector<EstimateRow>& estimates,
                 const EvaluationOptions& options = {});

// Per-estimate errors for plots: time since the first estimate, E_p and E_phi (nullopt where
// truth has no heading).
struct ErrorPoint {
  double t_s;
  double position_m;
  std::optional<double> heading_deg;
};
std::vector<ErrorPoint> error_series(const TruthTrack& truth, const std::vector<EstimateRow>& estimates,
                                     const EvaluationOptions& options = {});

// Files. Truth: stamp_ns,x_m,y_m,yaw_rad (yaw may be empty). Estimates:
// robot_id,stamp_ns,x_m,y_m,yaw_rad,cov_00..cov_22 (row-major 3x3),status,estimator.
// Loaders throw CsvError (core/csv_reader.hpp) naming the file and line of a malformed row.
// Beacon maps: load_beacon_map_csv / write_beacon_map_csv of core/csv_reader.hpp.
TruthTrack load_truth_csv(const std::string& path);
std::vector<EstimateRow> load_estimates_csv(const std::string& path);
void write_estimates_csv(const std::string& path, const std::vector<EstimateRow>& rows);
// estimate.csv's header and one row (without '\n'), for a writer of its own (beaconloc record).
std::string estimates_csv_header();
std::string estimates_csv_row(const EstimateRow& row);
void write_metrics_json(const std::string& path, const Metrics& m, const std::string& estimator,
                        const std::string& source);

}  // namespace beaconloc
