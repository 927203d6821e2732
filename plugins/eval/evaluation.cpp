#include "evaluation.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/pose_error.hpp"

namespace beaconloc {
namespace {

// Two-sided 95 % band of the chi-square distribution (2.5 % and 97.5 % quantiles).
constexpr double kChi2Band2[2] = {0.0506, 7.3778};
constexpr double kChi2Band3[2] = {0.2158, 9.3484};

// A stamp of the source clock in ns: the simulator's from 0, a recording's (from 0), the wall
// clock's since 1970; never negative.
StampNs stamp(const CsvReader& csv, const std::string& column) {
  StampNs v = 0;
  std::string problem;
  if (csv.read(column, v, 0, std::numeric_limits<StampNs>::max(), problem) != NumberError::kNone)
    throw CsvError(csv.where() + ": " + problem + " (a stamp in ns)");
  return v;
}

double number(const CsvReader& csv, const std::string& column, double limit) {
  double v = 0.0;
  std::string problem;
  if (csv.read(column, v, -limit, limit, problem) != NumberError::kNone)
    throw CsvError(csv.where() + ": " + problem);
  return v;
}
double position(const CsvReader& csv, const std::string& column) {
  return number(csv, column, kMaxMapCoordinateM);
}
double angle(const CsvReader& csv, const std::string& column) { return number(csv, column, kMaxAngleRad); }

void require_complete(const CsvReader& csv) {
  if (!csv.complete()) throw CsvError(csv.where() + ": expected " + std::to_string(csv.width()) + " columns");
}

const std::vector<std::string> kEstimateColumns = {
    "robot_id", "stamp_ns", "x_m",    "y_m",    "yaw_rad", "cov_00", "cov_01", "cov_02",
    "cov_10",   "cov_11",   "cov_12", "cov_20", "cov_21",  "cov_22", "status", "estimator"};

// Seconds from t0 to t, for any two stamps (their difference may not fit an int64).
double seconds_since(StampNs t0, StampNs t) {
  const auto u0 = static_cast<std::uint64_t>(t0), u = static_cast<std::uint64_t>(t);
  return t >= t0 ? static_cast<double>(u - u0) * 1e-9 : -static_cast<double>(u0 - u) * 1e-9;
}

PoseStatus status_from(const std::string& s, const std::string& where) {
  for (PoseStatus p :
       {PoseStatus::kInitializing, PoseStatus::kOk, PoseStatus::kDegraded, PoseStatus::kLost}) {
    if (s == to_string(p)) return p;
  }
  throw CsvError(where + ": unknown status '" + s + "'");
}

}  // namespace

const std::vector<Eigen::Vector2d>& significant_points_base_m() {
  // Seed 000, Section V (ERRATA: the fifth point is the mirror [-0.24, 0.2]).
  static const std::vector<Eigen::Vector2d> points = {
      {0.2, 0.0}, {0.0, 0.2}, {0.0, -0.2}, {-0.24, -0.2}, {-0.24, 0.2}};
  return points;
}

Metrics evaluate(const TruthTrack& truth, const std::vector<EstimateRow>& estimates,
                 const EvaluationOptions& options) {
  Metrics m;
  bool all_have_yaw = true;
  std::vector<std::pair<const EstimateRow*, TruthSample>> scored;
  for (const auto& row : estimates) {
    if (!publishable(row.estimate)) {  // refused where it was read; one here is a bug upstream
      throw std::invalid_argument("evaluate: an estimate at stamp " + std::to_string(row.estimate.stamp_ns) +
                                  " is not finite");
    }
    if (row.estimate.stamp_ns < options.score_from_ns) {
      ++m.samples_before_scoring;
      continue;
    }
    const auto t = truth.at(row.estimate.stamp_ns, options.max_truth_gap_ns);
    if (!t) {
      ++m.samples_without_truth;
      continue;
    }
    all_have_yaw = all_have_yaw && t->has_yaw;
    scored.emplace_back(&row, *t);
  }
  m.samples = scored.size();
  if (scored.empty()) return m;
  m.nees_dof = all_have_yaw ? 3 : 2;
  PoseErrorAccumulator position;  // eq. 33 (and eq. 34 where truth has heading)
  PoseErrorAccumulator heading;
  double sum_es = 0;
  std::size_t in_band = 0;
  std::vector<double> path_errors;
  for (const auto& [row, t] : scored) {
    const Pose2& est = row->estimate.pose_map_base;
    const Pose2& gt = t.pose_map_base;
    position.add(gt, est);
    if (t.has_yaw) {
      heading.add(gt, est);
      double es_sq = 0;  // eq. 35 at this step
      for (const auto& p : significant_points_base_m()) {
        es_sq += (transform_point(gt, p) - transform_point(est, p)).squaredNorm();
      }
      sum_es += std::sqrt(es_sq / static_cast<double>(significant_points_base_m().size()));
      const Eigen::Vector2d left(-std::sin(gt.z()), std::cos(gt.z()));
      path_errors.push_back((est.head<2>() - gt.head<2>()).dot(left));
    }
    double nees;
    if (m.nees_dof == 3) {
      Eigen::Vector3d e = gt - est;
      e.z() = wrap_angle_rad(e.z());
      nees = e.dot(row->estimate.covariance.ldlt().solve(e));
      in_band += nees >= kChi2Band3[0] && nees <= kChi2Band3[1];
    } else {
      const Eigen::Vector2d e = gt.head<2>() - est.head<2>();
      const Eigen::Matrix2d p = row->estimate.covariance.topLeftCorner<2, 2>();
      nees = e.dot(p.ldlt().solve(e));
      in_band += nees >= kChi2Band2[0] && nees <= kChi2Band2[1];
    }
  }
  m.position_rms_m = position.position_rms_m();
  m.position_mean_m = position.position_mean_m();
  m.position_max_m = position.position_max_m();
  m.nees_in_band_fraction = static_cast<double>(in_band) / static_cast<double>(scored.size());
  if (heading.samples()) {
    m.heading_rms_deg = heading.heading_rms_deg();
    m.significant_points_mean_m = sum_es / static_cast<double>(heading.samples());
    double mean = 0.0, max_abs = 0.0, square = 0.0;
    for (const double e : path_errors) {
      mean += e;
      square += e * e;
      max_abs = std::max(max_abs, std::abs(e));
    }
    const auto n = static_cast<double>(path_errors.size());
    mean /= n;
    double var = 0.0;
    for (const double e : path_errors) var += (e - mean) * (e - mean);
    m.path_error_std_m = std::sqrt(var / n);
    m.path_error_rms_m = std::sqrt(square / n);
    m.path_error_max_m = max_abs;
  }
  return m;
}

std::vector<ErrorPoint> error_series(const TruthTrack& truth, const std::vector<EstimateRow>& estimates,
                                     const EvaluationOptions& options) {
  std::vector<ErrorPoint> out;
  if (estimates.empty()) return out;
  const StampNs t0 = estimates.front().estimate.stamp_ns;
  for (const auto& row : estimates) {
    const auto t = truth.at(row.estimate.stamp_ns, options.max_truth_gap_ns);
    if (!t) continue;
    const Pose2& est = row.estimate.pose_map_base;
    ErrorPoint p{
        seconds_since(t0, row.estimate.stamp_ns), (t->pose_map_base.head<2>() - est.head<2>()).norm(), {}};
    if (t->has_yaw) p.heading_deg = wrap_angle_rad(t->pose_map_base.z() - est.z()) * 180.0 / M_PI;
    out.push_back(p);
  }
  return out;
}

TruthTrack load_truth_csv(const std::string& path) {
  CsvReader csv(path, {"stamp_ns", "x_m", "y_m", "yaw_rad"});
  TruthTrack truth;
  while (csv.next()) {
    require_complete(csv);
    const bool has_yaw = !csv.cell("yaw_rad").empty();
    truth.add(stamp(csv, "stamp_ns"),
              {position(csv, "x_m"), position(csv, "y_m"), has_yaw ? angle(csv, "yaw_rad") : 0.0}, has_yaw);
  }
  return truth;
}

std::vector<EstimateRow> load_estimates_csv(const std::string& path) {
  CsvReader csv(path, kEstimateColumns);
  std::vector<EstimateRow> rows;
  while (csv.next()) {
    require_complete(csv);
    EstimateRow r;
    r.robot_id = csv.cell("robot_id");
    r.estimate.stamp_ns = stamp(csv, "stamp_ns");
    r.estimate.pose_map_base = {position(csv, "x_m"), position(csv, "y_m"), angle(csv, "yaw_rad")};
    for (int i = 0; i < 9; ++i) {
      r.estimate.covariance(i / 3, i % 3) = number(
          csv, "cov_" + std::to_string(i / 3) + std::to_string(i % 3), std::numeric_limits<double>::max());
    }
    r.estimate.status = status_from(csv.cell("status"), csv.where());
    r.estimator = csv.cell("estimator");
    // Refused here, where the file and line are known, as every reader of poses refuses it
    // (found by fuzz_eval_csv: an asymmetric covariance loaded, then evaluate() threw).
    if (!publishable(r.estimate)) {
      throw CsvError(csv.where() + ": not a pose a localizer publishes (a covariance that is not symmetric "
                                   "with non-negative variances, or a variance beyond (1000 km)^2)");
    }
    rows.push_back(r);
  }
  return rows;
}

void write_estimates_csv(const std::string& path, const std::vector<EstimateRow>& rows) {
  // Every reader of poses refuses a non-finite one at its door (localizer, bridge, recorder): one
  // here is a bug upstream, and no file gets it.
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!publishable(rows[i].estimate)) {
      throw std::invalid_argument("'" + path + "': estimate " + std::to_string(i) + " (stamp " +
                                  std::to_string(rows[i].estimate.stamp_ns) +
                                  ") is not finite; nothing written");
    }
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  std::string text = estimates_csv_header() + '\n';
  for (const auto& r : rows) text += estimates_csv_row(r) + '\n';
  if (!(out << text).flush()) throw std::runtime_error("writing '" + path + "' failed");
}

std::string estimates_csv_header() {
  std::string header;
  for (std::size_t i = 0; i < kEstimateColumns.size(); ++i) header += (i ? "," : "") + std::string(kEstimateColumns[i]);
  return header;
}

std::string estimates_csv_row(const EstimateRow& r) {
  // Numbers in the shortest text that reads back to the same double: two runs' files are equal
  // exactly when their estimates are.
  const auto& e = r.estimate;
  std::string row = r.robot_id + ',' + std::to_string(e.stamp_ns);
  for (double v : {e.pose_map_base.x(), e.pose_map_base.y(), e.pose_map_base.z()}) {
    row += ',';
    append_decimal(row, v);
  }
  for (int i = 0; i < 9; ++i) {
    row += ',';
    append_decimal(row, e.covariance(i / 3, i % 3));
  }
  row += ',' + std::string(to_string(e.status)) + ',' + r.estimator;
  return row;
}

void write_metrics_json(const std::string& path, const Metrics& m, const std::string& estimator,
                        const std::string& source) {
  // A figure is written only where something was scored: with no sample, every figure is null
  // (a run that scored nothing has no error of 0 m). A figure that is not finite is never
  // written: the evaluation refuses it, and the file is not left half-written.
  const bool scored = m.samples > 0;
  auto figure = [&](double v) { return scored ? std::optional<double>(v) : std::nullopt; };
  for (const auto& v : {figure(m.position_rms_m), figure(m.position_mean_m), figure(m.position_max_m),
                        m.heading_rms_deg, m.significant_points_mean_m, figure(m.nees_in_band_fraction)}) {
    if (v && !std::isfinite(*v)) throw std::runtime_error("'" + path + "': a metric is not finite");
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  auto quoted = [](const std::string& s) {
    std::string q = "\"";
    for (char ch : s) {
      if (ch == '"' || ch == '\\') q += '\\';
      q += ch;
    }
    return q + "\"";
  };
  auto optional = [](const std::optional<double>& v) {
    std::ostringstream s;
    s << std::setprecision(6);
    if (v)
      s << *v;
    else
      s << "null";
    return s.str();
  };
  out << std::setprecision(6) << "{\n"
      << "  \"estimator\": " << quoted(estimator) << ",\n"
      << "  \"source\": " << quoted(source) << ",\n"
      << "  \"samples\": " << m.samples << ",\n"
      << "  \"samples_without_truth\": " << m.samples_without_truth << ",\n"
      << "  \"samples_before_scoring\": " << m.samples_before_scoring << ",\n"
      << "  \"position_rms_m\": " << optional(figure(m.position_rms_m)) << ",\n"
      << "  \"position_mean_m\": " << optional(figure(m.position_mean_m)) << ",\n"
      << "  \"position_max_m\": " << optional(figure(m.position_max_m)) << ",\n"
      << "  \"heading_rms_deg\": " << optional(m.heading_rms_deg) << ",\n"
      << "  \"significant_points_mean_m\": " << optional(m.significant_points_mean_m) << ",\n"
      << "  \"nees_in_band_fraction\": " << optional(figure(m.nees_in_band_fraction)) << ",\n"
      << "  \"nees_dof\": " << m.nees_dof << "\n"
      << "}\n";
  if (!out.flush()) throw std::runtime_error("writing '" + path + "' failed");
}

}  // namespace beaconloc
