#include "replay_source.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/speed_of_sound.hpp"
#include "bus_recording.hpp"

namespace beaconloc {
namespace {

// An odometry row's interval (dt_s) is at most an hour: a longer one is no odometry.
constexpr double kMaxOdometryIntervalS = 3600.0;
constexpr double kAnyFinite = std::numeric_limits<double>::max();

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

void ReplaySource::note_if_earlier(const std::string& file, std::size_t line, StampNs previous_ns, StampNs stamp_ns) {
  if (stamp_ns >= previous_ns || notes_.size() >= 20) return;
  // Each row carries its own stamp: the rows are replayed in stamp order, and this is said.
  notes_.push_back(directory_ + "/" + file + ".csv:" + std::to_string(line) + ": " +
                   std::to_string(ns_to_s(previous_ns - stamp_ns)) + " s earlier than the row before; " + file +
                   " are replayed in stamp order");
}

bool ReplaySource::complete(const CsvReader& csv, const std::string& file) {
  if (csv.complete()) return true;
  refuse(file, csv.line(), "malformed_row", csv.cell_count_problem());
  return false;
}

bool ReplaySource::take(const CsvReader& csv, const std::string& file, const std::string& column, double& out,
                        double min, double max) {
  std::string problem;
  const NumberError e = csv.read(column, out, min, max, problem);
  if (e == NumberError::kNone) return true;
  refuse(file, csv.line(), e == NumberError::kNotDecimal ? "malformed_row" : "invalid_" + column, problem);
  return false;
}

ReplaySource::ReplaySource(const std::string& directory, ReplayOptions options)
    : directory_(directory), options_(options) {
  if (!(options_.wheel_base_m > 0.0 && options_.wheel_base_m <= kMaxWheelBaseM))
    throw ReplayError("replay wheel base must be in (0, " + std::to_string(kMaxWheelBaseM) + "] m");
  if (!(options_.odometry_k_v_m >= 0.0 && options_.odometry_k_v_m <= ReplayOptions::kMaxOdometryKvM))
    throw ReplayError("replay odometry k_v must be in [0, " + std::to_string(ReplayOptions::kMaxOdometryKvM) + "] m");
  if (!(options_.odometry_heading_arw_rad_per_sqrt_s >= 0.0 &&
        options_.odometry_heading_arw_rad_per_sqrt_s <= ReplayOptions::kMaxHeadingArwRadPerSqrtS))
    throw ReplayError("replay heading angle random walk must be in [0, " +
                      std::to_string(ReplayOptions::kMaxHeadingArwRadPerSqrtS) + "] rad/sqrt(s)");
  load_beacons(directory + "/beacons.csv");
  const bool bus = static_cast<bool>(std::ifstream(directory + "/" + bus_recording::kOdometryFile));
  if (bus && std::ifstream(directory + "/odom.csv")) {
    throw ReplayError(directory + ": both odom.csv (a dataset) and odometry.csv (a recording of the bus)");
  }
  if (bus) {
    load_bus_recording();
  } else {
    load_dataset();
  }
  // Merge the files by stamp; within a file, order is kept (stable).
  std::stable_sort(events_.begin(), events_.end(),
                   [](const SourceEvent& a, const SourceEvent& b) { return a.stamp_ns < b.stamp_ns; });
  if (events_.empty()) throw ReplayError(directory + ": no odometry, range or truth rows");
}

void ReplaySource::load_dataset() {
  const std::string& directory = directory_;
  load_odometry(directory + "/odom.csv");
  // A recording hears its beacons one way: ranges, or pulse arrivals without a firing time.
  const bool has_pulses = static_cast<bool>(std::ifstream(directory + "/pulses.csv"));
  if (has_pulses && std::ifstream(directory + "/ranges.csv")) {
    throw ReplayError(directory + ": both ranges.csv and pulses.csv; a recording has one or the other");
  }
  if (has_pulses) {
    load_pulses(directory + "/pulses.csv");
  } else {
    load_ranges(directory + "/ranges.csv");
  }
  load_truth(directory + "/gt.csv");
}

ReceiverArray ReplaySource::single_receiver() {
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

Eigen::Matrix2d ReplaySource::odometry_covariance(bool own_wheels, const Eigen::Vector2d& wheels_mps, double v_mps,
                                                  double dt_s, double half_track_m) const {
  if (own_wheels) return (options_.odometry_k_v_m * wheels_mps.cwiseAbs() / dt_s).asDiagonal();
  // Noise on (v, omega), independent, carried exactly by the wheel speeds [v_R, v_L] = A [v, omega]
  // that express them: cov = A diag(sigma_v^2, sigma_omega^2) A^T, A = [[1, b], [1, -b]], b the
  // half track used. The filters map it back (seed 000 eq. 16) to the same (v, omega) noise for
  // any b: the made-up wheel base no longer decides how much the heading is trusted.
  // Written out, so that it is exactly symmetric.
  const double arw = options_.odometry_heading_arw_rad_per_sqrt_s;
  const double speed_variance = options_.odometry_k_v_m * std::abs(v_mps) / dt_s;
  const double rate_variance_in_wheel_speed = half_track_m * half_track_m * arw * arw / dt_s;
  Eigen::Matrix2d c;
  c << speed_variance + rate_variance_in_wheel_speed, speed_variance - rate_variance_in_wheel_speed,
      speed_variance - rate_variance_in_wheel_speed, speed_variance + rate_variance_in_wheel_speed;
  return c;
}

void ReplaySource::load_odometry(const std::string& path) {
  CsvReader csv = open(path, {"t_s", "dt_s", "v_mps", "omega_radps"});
  const bool has_half_track = csv.has_column("half_track_m");
  StampNs previous_start = 0, previous_end = std::numeric_limits<StampNs>::min();
  std::size_t previous_line = 0;
  while (csv.next()) {
    double t = 0, dt = 0, v = 0, w = 0, half_track = options_.wheel_base_m / 2.0;
    if (!complete(csv, "odom") || !take(csv, "odom", "t_s", t, 0.0, kMaxFileStampS) ||
        !take(csv, "odom", "dt_s", dt, 0.0, kMaxOdometryIntervalS) ||
        !take(csv, "odom", "v_mps", v, -kMaxWheelSpeedMps, kMaxWheelSpeedMps) ||
        !take(csv, "odom", "omega_radps", w, -kAnyFinite, kAnyFinite) ||
        (has_half_track && !take(csv, "odom", "half_track_m", half_track, 0.0, kMaxWheelBaseM / 2.0))) {
      continue;
    }
    if (!(dt > 0.0)) {
      refuse("odom", csv.line(), "invalid_dt_s", "dt_s " + csv.cell("dt_s") + " must be > 0");
      continue;
    }
    if (!(half_track > 0.0)) {
      refuse("odom", csv.line(), "invalid_half_track_m",
             "half_track_m " + csv.cell("half_track_m") + " must be > 0");
      continue;
    }
    if (t + dt > kMaxFileStampS) {
      refuse("odom", csv.line(), "invalid_dt_s", range_problem("t_s + dt_s", t + dt, 0.0, kMaxFileStampS));
      continue;
    }
    // (v, omega) become wheel speeds v +- omega * B/2: each within the physical limit.
    const Eigen::Vector2d wheels_mps = wheel_speeds_mps(v, w, 2.0 * half_track);
    const double right = wheels_mps(0), left = wheels_mps(1);
    if (!(std::abs(right) <= kMaxWheelSpeedMps && std::abs(left) <= kMaxWheelSpeedMps)) {
      std::ostringstream why;
      why << "omega_radps " << csv.cell("omega_radps") << " turns the wheels at " << right << " and " << left
          << " m/s, beyond " << kMaxWheelSpeedMps << " m/s";
      refuse("odom", csv.line(), "invalid_omega_radps", why.str());
      continue;
    }
    // (v, omega) held over [t_s, t_s + dt_s): the Odometry topic stamps the end of the interval.
    // Intervals follow each other; 1 ms of overlap is rounding in the recording's stamps. One
    // sample per stamp: a second interval ending at the same stamp is a duplicate.
    const StampNs start_ns = s_to_ns(t), end_ns = s_to_ns(t + dt);
    if (previous_end != std::numeric_limits<StampNs>::min()) {
      if (end_ns == previous_end) {
        refuse("odom", csv.line(), "duplicate_row",
               std::string(start_ns == previous_start ? "the same interval"
                                                      : "an interval ending at the same stamp") +
                   " as line " + std::to_string(previous_line));
        continue;
      }
      if (end_ns < previous_end || start_ns < previous_end - kNsPerMillisecond) {
        refuse("odom", csv.line(), "out_of_order_row", "interval starts before the previous one ends");
        continue;
      }
    }
    previous_start = start_ns;
    previous_end = end_ns;
    previous_line = csv.line();
    SourceEvent e;
    e.kind = SourceEvent::Kind::kOdometry;
    e.stamp_ns = end_ns;
    e.odometry.stamp_ns = end_ns;
    e.odometry.wheel_base_m = 2.0 * half_track;
    e.odometry.wheel_velocity_right_mps = right;
    e.odometry.wheel_velocity_left_mps = left;
    e.odometry.wheel_velocity_covariance = odometry_covariance(has_half_track, wheels_mps, v, dt, half_track);
    events_.push_back(e);
  }
}

void ReplaySource::load_ranges(const std::string& path) {
  CsvReader csv = open(path, {"t_s", "beacon_id", "range_m"});
  const double c = speed_of_sound_mps(options_.reference_temperature_c);
  StampNs previous = std::numeric_limits<StampNs>::min();
  std::uint64_t sequence = 0;
  // Each measurement once: the line of the range to each beacon at each stamp (one receiver).
  std::map<std::pair<StampNs, std::uint32_t>, std::size_t> measured;
  while (csv.next()) {
    double t = 0, range = 0;
    std::uint32_t id = 0;
    std::string problem;
    if (!complete(csv, "ranges") || !take(csv, "ranges", "t_s", t, 0.0, kMaxFileStampS)) continue;
    if (csv.read_id("beacon_id", id, problem) != NumberError::kNone) {
      refuse("ranges", csv.line(), "malformed_row", problem);
      continue;
    }
    // Negative ranges, and ranges beyond the decoder's limits, travel on: the decoder refuses and
    // counts them. Beyond any beacon system's reach they are refused here.
    if (!take(csv, "ranges", "range_m", range, -kMaxRangeM, kMaxRangeM)) continue;
    const StampNs arrival_ns = s_to_ns(t);
    const auto [first, fresh] = measured.emplace(std::make_pair(arrival_ns, id), csv.line());
    if (!fresh) {
      refuse("ranges", csv.line(), "duplicate_row",
             "a second range to beacon " + std::to_string(id) + " at t_s " + csv.cell("t_s") +
                 " (first at line " + std::to_string(first->second) + "); the first is replayed");
      continue;
    }
    note_if_earlier("ranges", csv.line(), previous, arrival_ns);
    previous = std::max(previous, arrival_ns);
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

void ReplaySource::load_pulses(const std::string& path) {
  beacon_input_ = BeaconInput::kPulseArrivals;
  CsvReader csv = open(path, {"t_s", "mark"});
  StampNs previous = std::numeric_limits<StampNs>::min();
  std::uint64_t sequence = 0;
  while (csv.next()) {
    double t = 0;
    if (!complete(csv, "pulses") || !take(csv, "pulses", "t_s", t, 0.0, kMaxFileStampS)) continue;
    const std::string mark = csv.cell("mark");
    const std::optional<PulseMark> parsed = bus_recording::parse_pulse_mark(mark);
    if (!parsed) {
      refuse("pulses", csv.line(), "invalid_mark", "mark '" + mark + "' is not single, double or not_reported");
      continue;
    }
    const StampNs arrival_ns = s_to_ns(t);
    note_if_earlier("pulses", csv.line(), previous, arrival_ns);
    previous = std::max(previous, arrival_ns);
    SourceEvent e;
    e.kind = SourceEvent::Kind::kPulse;
    e.stamp_ns = arrival_ns;
    e.pulse.stamp_ns = arrival_ns;
    e.pulse.receiver_id = 0;  // one receiver at the robot's centre (receivers())
    e.pulse.mark = *parsed;
    e.pulse.sequence_number = sequence++;
    events_.push_back(e);
  }
}

void ReplaySource::load_truth(const std::string& path) {
  if (!std::ifstream(path)) return;  // truth is optional
  CsvReader csv = open(path, {"t_s", "x_m", "y_m"});
  truth_has_yaw_ = csv.has_column("yaw_rad");
  StampNs previous = std::numeric_limits<StampNs>::min();
  std::size_t previous_line = 0;
  while (csv.next()) {
    double t = 0, x = 0, y = 0, yaw = 0.0;
    if (!complete(csv, "gt") || !take(csv, "gt", "t_s", t, 0.0, kMaxFileStampS) ||
        !take(csv, "gt", "x_m", x, -kMaxMapCoordinateM, kMaxMapCoordinateM) ||
        !take(csv, "gt", "y_m", y, -kMaxMapCoordinateM, kMaxMapCoordinateM) ||
        (truth_has_yaw_ && !take(csv, "gt", "yaw_rad", yaw, -kMaxAngleRad, kMaxAngleRad))) {
      continue;
    }
    const StampNs stamp = s_to_ns(t);
    if (stamp == previous) {
      refuse("gt", csv.line(), "duplicate_row", "the same t_s as line " + std::to_string(previous_line));
      continue;
    }
    if (stamp < previous) {
      refuse("gt", csv.line(), "out_of_order_row", "not after the previous truth row");
      continue;
    }
    previous = stamp;
    previous_line = csv.line();
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
