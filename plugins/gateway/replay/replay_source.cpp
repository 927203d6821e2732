#include "replay_source.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/speed_of_sound.hpp"

namespace beaconloc {
namespace {

// Times the replay can stamp: within 4.6e9 s (146 years) of the recording's zero, so that a time
// and a time minus a time of flight as long are int64 nanoseconds.
bool stampable(double t_s) { return std::abs(t_s) <= 4.6e9; }

}  // namespace

CsvReader ReplaySource::open(const std::string& path, const std::vector<std::string>& columns) {
  try {
    return CsvReader(path, columns);
  } catch (const CsvError& e) {
    throw ReplayError(e.what());
  }
}

void ReplaySource::refuse(const std::string& file, std::size_t line, const std::string& reason,
                          const std::string& detail) {
  load_counts_.reject(file + "." + reason);
  if (problems_.size() < 20)
    problems_.push_back(directory_ + "/" + file + ".csv:" + std::to_string(line) + ": " + detail);
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
  // A beacon map with a hole would mislead every estimator: a bad row refuses the recording.
  try {
    map_ = load_beacon_map_csv(path);
  } catch (const CsvError& e) {
    throw ReplayError(e.what());
  }
}

void ReplaySource::load_odometry(const std::string& path) {
  CsvReader csv = open(path, {"t_s", "dt_s", "v_mps", "omega_radps"});
  const bool has_half_track = csv.has_column("half_track_m");
  StampNs previous_end = std::numeric_limits<StampNs>::min();
  while (csv.next()) {
    double t = 0, dt = 0, v = 0, w = 0, half_track = options_.wheel_base_m / 2.0;
    if (!csv.complete() || !parse_finite(csv.cell("t_s"), t) || !parse_finite(csv.cell("dt_s"), dt) ||
        !parse_finite(csv.cell("v_mps"), v) || !parse_finite(csv.cell("omega_radps"), w) ||
        (has_half_track && !parse_finite(csv.cell("half_track_m"), half_track))) {
      refuse("odom", csv.line(), "malformed_row", "not " + std::to_string(csv.width()) + " finite numbers");
      continue;
    }
    if (!(dt > 0.0) || !(half_track > 0.0)) {
      refuse("odom", csv.line(), "invalid_value", "dt_s and half_track_m must be > 0");
      continue;
    }
    if (!stampable(t) || !stampable(t + dt)) {
      refuse("odom", csv.line(), "invalid_value", "t_s and t_s + dt_s must lie within 4.6e9 s of 0");
      continue;
    }
    // (v, omega) held over [t_s, t_s + dt_s): the Odometry topic stamps the end of the interval.
    // Intervals follow each other; 1 ms of overlap is rounding in the recording's stamps.
    const StampNs end_ns = s_to_ns(t + dt);
    if (previous_end != std::numeric_limits<StampNs>::min() &&
        s_to_ns(t) < previous_end - kNsPerMillisecond) {
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
  CsvReader csv = open(path, {"t_s", "beacon_id", "range_m"});
  const double c = speed_of_sound_mps(options_.reference_temperature_c);
  StampNs previous = std::numeric_limits<StampNs>::min();
  std::uint64_t sequence = 0;
  while (csv.next()) {
    double t = 0, range = 0;
    std::uint32_t id = 0;
    if (!csv.complete() || !parse_finite(csv.cell("t_s"), t) || !parse_id(csv.cell("beacon_id"), id) ||
        !parse_finite(csv.cell("range_m"), range)) {
      refuse("ranges", csv.line(), "malformed_row", "not t_s, an unsigned beacon id and a finite range");
      continue;
    }
    if (!stampable(t) || !stampable(range / c)) {
      refuse("ranges", csv.line(), "invalid_value",
             "t_s and the time of flight must lie within 4.6e9 s of 0");
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
  if (!std::ifstream(path)) return;  // truth is optional
  CsvReader csv = open(path, {"t_s", "x_m", "y_m"});
  truth_has_yaw_ = csv.has_column("yaw_rad");
  StampNs previous = std::numeric_limits<StampNs>::min();
  while (csv.next()) {
    double t = 0, x = 0, y = 0, yaw = 0.0;
    if (!csv.complete() || !parse_finite(csv.cell("t_s"), t) || !parse_finite(csv.cell("x_m"), x) ||
        !parse_finite(csv.cell("y_m"), y) || (truth_has_yaw_ && !parse_finite(csv.cell("yaw_rad"), yaw))) {
      refuse("gt", csv.line(), "malformed_row", "not finite t_s, x_m, y_m[, yaw_rad]");
      continue;
    }
    if (!stampable(t)) {
      refuse("gt", csv.line(), "invalid_value", "t_s must lie within 4.6e9 s of 0");
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
