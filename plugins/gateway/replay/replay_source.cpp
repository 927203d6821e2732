#include "replay_source.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc {
namespace {

// A CSV file with a header row; columns are found by name.
class CsvFile {
 public:
  CsvFile(const std::string& path, const std::vector<std::string>& required, bool optional_file = false)
      : path_(path), in_(path) {
    if (!in_) {
      if (optional_file) return;
      throw ReplayError("cannot read '" + path + "'");
    }
    std::string header;
    if (!std::getline(in_, header)) throw ReplayError(path + ":1: empty file, expected a header row");
    const auto names = split(strip(header));
    for (std::size_t i = 0; i < names.size(); ++i) columns_[names[i]] = i;
    for (const auto& r : required) {
      if (!columns_.count(r)) throw ReplayError(path + ":1: header lacks column '" + r + "'");
    }
    width_ = names.size();
    open_ = true;
  }
  bool open() const { return open_; }
  bool has(const std::string& column) const { return columns_.count(column) > 0; }
  // Next data row; false at the end. Blank lines are skipped.
  bool next(std::vector<std::string>& cells) {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_;
      line = strip(line);
      if (line.empty()) continue;
      cells = split(line);
      return true;
    }
    return false;
  }
  std::size_t line() const { return line_; }  // of the row last read; the header is line 1
  std::size_t width() const { return width_; }
  std::size_t column(const std::string& name) const { return columns_.at(name); }
  const std::string& path() const { return path_; }

 private:
  static std::string strip(std::string s) {
    while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
    return s;
  }
  static std::vector<std::string> split(const std::string& line) {
    std::vector<std::string> out;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) out.push_back(cell);
    if (!line.empty() && line.back() == ',') out.emplace_back();
    return out;
  }
  std::string path_;
  std::ifstream in_;
  std::map<std::string, std::size_t> columns_;
  std::size_t width_ = 0;
  std::size_t line_ = 1;
  bool open_ = false;
};

// A finite number, the whole cell.
bool parse_number(const std::string& cell, double& out) {
  if (cell.empty()) return false;
  errno = 0;
  char* end = nullptr;
  out = std::strtod(cell.c_str(), &end);
  return errno == 0 && end == cell.c_str() + cell.size() && std::isfinite(out);
}

bool parse_id(const std::string& cell, std::uint32_t& out) {
  double v = 0.0;
  if (!parse_number(cell, v) || v < 0.0 || v >= 4294967295.0 || v != std::floor(v)) return false;
  out = static_cast<std::uint32_t>(v);
  return true;
}

}  // namespace

void ReplaySource::refuse(const std::string& file, std::size_t line, const std::string& reason,
                          const std::string& detail) {
  load_counts_.reject(file + "." + reason);
  if (problems_.size() < 20) problems_.push_back(directory_ + "/" + file + ".csv:" + std::to_string(line) + ": " + detail);
}

ReplaySource::ReplaySource(const std::string& directory, ReplayOptions options)
    : directory_(directory), options_(options) {
  if (!(options_.wheel_base_m > 0.0)) throw ReplayError("replay wheel base must be > 0");
  load_beacons(directory + "/beacons.csv");
  load_odometry(directory + "/odom.csv");
  load_ranges(directory + "/ranges.csv");
  load_truth(directory + "/gt.csv");
  // Merge the files by stamp; within a file, order is kept (stable).
  std::stable_sort(events_.begin(), events_.end(),
                   [](const SourceEvent& a, const SourceEvent& b) { return a.stamp_ns < b.stamp_ns; });
  if (events_.empty()) throw ReplayError(directory + ": no odometry, range or truth rows");
}

ReceiverArray ReplaySource::receivers() const {
  ReceiverArray a;  // one receiver (radio, UWB tag) at the robot's centre
  a.receivers_base_m.push_back(Eigen::Vector2d::Zero());
  return a;
}

void ReplaySource::load_beacons(const std::string& path) {
  CsvFile csv(path, {"beacon_id", "x_m", "y_m", "z_m"});
  std::vector<Beacon> beacons;
  std::vector<std::string> cells;
  while (csv.next(cells)) {
    Beacon b;
    double x = 0, y = 0, z = 0;
    if (cells.size() != csv.width() || !parse_id(cells[csv.column("beacon_id")], b.id) ||
        !parse_number(cells[csv.column("x_m")], x) || !parse_number(cells[csv.column("y_m")], y) ||
        !parse_number(cells[csv.column("z_m")], z)) {
      // A beacon map with a hole would mislead every estimator: refuse the recording.
      throw ReplayError(path + ":" + std::to_string(csv.line()) + ": malformed beacon row");
    }
    for (const auto& other : beacons) {
      if (other.id == b.id) throw ReplayError(path + ":" + std::to_string(csv.line()) + ": beacon id repeated");
    }
    b.position_map_m = {x, y, z};
    beacons.push_back(b);
  }
  if (beacons.empty()) throw ReplayError(path + ": no beacons");
  map_ = BeaconMap(beacons);
}

void ReplaySource::load_odometry(const std::string& path) {
  CsvFile csv(path, {"t_s", "dt_s", "v_mps", "omega_radps"});
  const bool has_half_track = csv.has("half_track_m");
  std::vector<std::string> cells;
  StampNs previous_end = std::numeric_limits<StampNs>::min();
  while (csv.next(cells)) {
    double t = 0, dt = 0, v = 0, w = 0, half_track = options_.wheel_base_m / 2.0;
    if (cells.size() != csv.width() || !parse_number(cells[csv.column("t_s")], t) ||
        !parse_number(cells[csv.column("dt_s")], dt) || !parse_number(cells[csv.column("v_mps")], v) ||
        !parse_number(cells[csv.column("omega_radps")], w) ||
        (has_half_track && !parse_number(cells[csv.column("half_track_m")], half_track))) {
      refuse("odom", csv.line(), "malformed_row", "not " + std::to_string(csv.width()) + " finite numbers");
      continue;
    }
    if (!(dt > 0.0) || !(half_track > 0.0)) {
      refuse("odom", csv.line(), "invalid_value", "dt_s and half_track_m must be > 0");
      continue;
    }
    // (v, omega) held over [t_s, t_s + dt_s): the Odometry topic stamps the end of the interval.
    // Intervals follow each other; 1 ms of overlap is rounding in the recording's stamps.
    const StampNs end_ns = s_to_ns(t + dt);
    if (previous_end != std::numeric_limits<StampNs>::min() && s_to_ns(t) < previous_end - kNsPerMillisecond) {
      refuse("odom", csv.line(), "out_of_order_row", "interval starts before the previous one ends");
      continue;
    }
    previous_end = end_ns;
    SourceEvent e;
    e.kind = SourceEvent::Kind::kOdometry;
    e.stamp_ns = end_ns;
    e.odometry.stamp_ns = end_ns;
    e.odometry.wheel_base_m = 2.0 * half_track;
    e.odometry.wheel_velocity_right_mps = v + w * half_track;
    e.odometry.wheel_velocity_left_mps = v - w * half_track;
    e.odometry.wheel_velocity_covariance.diagonal()
        << options_.odometry_k_v_m * std::abs(e.odometry.wheel_velocity_right_mps) / dt,
        options_.odometry_k_v_m * std::abs(e.odometry.wheel_velocity_left_mps) / dt;
    events_.push_back(e);
  }
}

void ReplaySource::load_ranges(const std::string& path) {
  CsvFile csv(path, {"t_s", "beacon_id", "range_m"});
  const double c = speed_of_sound_mps(options_.reference_temperature_c);
  std::vector<std::string> cells;
  StampNs previous = std::numeric_limits<StampNs>::min();
  std::uint64_t sequence = 0;
  while (csv.next(cells)) {
    double t = 0, range = 0;
    std::uint32_t id = 0;
    if (cells.size() != csv.width() || !parse_number(cells[csv.column("t_s")], t) ||
        !parse_id(cells[csv.column("beacon_id")], id) || !parse_number(cells[csv.column("range_m")], range)) {
      refuse("ranges", csv.line(), "malformed_row", "not t_s, an unsigned beacon id and a finite range");
      continue;
    }
    const StampNs arrival_ns = s_to_ns(t);
    if (arrival_ns < previous && notes_.size() < 20) {
      // Each row carries its own stamp: the rows are replayed in stamp order, and this is said.
      notes_.push_back(directory_ + "/ranges.csv:" + std::to_string(csv.line()) + ": " +
                       std::to_string(ns_to_s(previous - arrival_ns)) +
                       " s earlier than the row before; ranges are replayed in stamp order");
    }
    previous = std::max(previous, arrival_ns);
    // Negative or absurd ranges travel on as they are: the decoder refuses and counts them.
    SourceEvent e;
    e.kind = SourceEvent::Kind::kTof;
    e.stamp_ns = arrival_ns;
    e.true_beacon_id = id;
    e.tof.beacon_id = id;
    e.tof.receiver_id = 0;
    e.tof.tof_s = range / c;
    e.tof.fire_stamp_ns = arrival_ns - s_to_ns(e.tof.tof_s);
    e.tof.beacon_temperature_c = options_.reference_temperature_c;
    e.tof.sequence_number = sequence++;
    events_.push_back(e);
  }
}

void ReplaySource::load_truth(const std::string& path) {
  CsvFile csv(path, {"t_s", "x_m", "y_m"}, /*optional_file=*/true);
  if (!csv.open()) return;
  truth_has_yaw_ = csv.has("yaw_rad");
  std::vector<std::string> cells;
  StampNs previous = std::numeric_limits<StampNs>::min();
  while (csv.next(cells)) {
    double t = 0, x = 0, y = 0, yaw = 0.0;
    if (cells.size() != csv.width() || !parse_number(cells[csv.column("t_s")], t) ||
        !parse_number(cells[csv.column("x_m")], x) || !parse_number(cells[csv.column("y_m")], y) ||
        (truth_has_yaw_ && !parse_number(cells[csv.column("yaw_rad")], yaw))) {
      refuse("gt", csv.line(), "malformed_row", "not finite t_s, x_m, y_m[, yaw_rad]");
      continue;
    }
    const StampNs stamp = s_to_ns(t);
    if (stamp <= previous) {
      refuse("gt", csv.line(), "out_of_order_row", "not after the previous truth row");
      continue;
    }
    previous = stamp;
    SourceEvent e;
    e.kind = SourceEvent::Kind::kTruth;
    e.stamp_ns = stamp;
    e.has_truth = true;
    e.truth_map_base = {x, y, wrap_angle_rad(yaw)};
    e.truth_has_yaw = truth_has_yaw_;
    events_.push_back(e);
  }
}

void ReplaySource::advance(StampNs until_ns, std::vector<SourceEvent>& out) {
  while (next_ < events_.size() && events_[next_].stamp_ns <= until_ns) out.push_back(events_[next_++]);
}

}  // namespace beaconloc
