// ReplaySource over a recording of the bus (bus_recording.hpp, docs/replay-format.md "Recordings of
// the bus"): each row becomes the sample it was on the bus, with the very numbers it carried. The
// replay judges nothing the bus did not: a negative TOF or an out-of-order odometry stamp travels
// on for the decoder and the localizer to refuse and count, as they did live. Refused here, and
// counted by reason, are only rows that are no sample at all: a cell that is not a number, a
// stamp outside [0, kMaxFileStampS], an id beyond 32 bits, a TOF beyond kMaxRecordedTofS.
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/limits.hpp"
#include "bus_recording.hpp"
#include "replay_source.hpp"

namespace beaconloc {
namespace {

constexpr double kAnyFinite = std::numeric_limits<double>::max();
constexpr std::int64_t kMaxStampNs = static_cast<std::int64_t>(kMaxFileStampS * 1e9);
constexpr std::int64_t kMaxId = std::numeric_limits<std::uint32_t>::max();  // kBeaconUnidentified included
constexpr std::int64_t kMaxSequence = std::numeric_limits<std::int64_t>::max();
// Sound crosses 1.2 km in an hour's hundredth: no beacon system measures a longer flight, and the
// arrival stamp (fire + TOF) must stay a representable time.
constexpr double kMaxRecordedTofS = 3600.0;

bool exists(const std::string& path) { return static_cast<bool>(std::ifstream(path)); }

// A float of a scan: a decimal number, or inf, -inf, nan as the bus's float was.
NumberError parse_beam(const std::string& text, float& out) {
  if (text == "inf" || text == "-inf") {
    out = text[0] == '-' ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity();
    return NumberError::kNone;
  }
  if (text == "nan") {
    out = std::numeric_limits<float>::quiet_NaN();
    return NumberError::kNone;
  }
  double value = 0.0;
  const NumberError e = parse_decimal(text, value);
  if (e != NumberError::kNone) return e;
  // Written from a float, exactly: a value no float holds was not written by a recorder.
  if (static_cast<double>(static_cast<float>(value)) != value) return NumberError::kOutOfRange;
  out = static_cast<float>(value);
  return NumberError::kNone;
}

}  // namespace

bool ReplaySource::take_integer(const CsvReader& csv, const std::string& file, const std::string& column,
                                std::int64_t& out, std::int64_t min, std::int64_t max) {
  std::string problem;
  const NumberError e = csv.read(column, out, min, max, problem);
  if (e == NumberError::kNone) return true;
  refuse(file, csv.line(), e == NumberError::kNotDecimal ? "malformed_row" : "invalid_" + column, problem);
  return false;
}

void ReplaySource::load_bus_recording() {
  const std::string& dir = directory_;
  load_bus_odometry(dir + "/" + bus_recording::kOdometryFile);
  const std::string tofs = dir + "/" + bus_recording::kTofFile,
                    pulses = dir + "/" + bus_recording::kPulseFile;
  if (exists(tofs) && exists(pulses)) {
    throw ReplayError(dir + ": both " + bus_recording::kTofFile + " and " + bus_recording::kPulseFile +
                      "; a robot hears its beacons one way");
  }
  if (exists(pulses)) {
    load_bus_pulses(pulses);
  } else if (exists(tofs)) {
    load_bus_tofs(tofs);
  }
  if (exists(dir + "/" + bus_recording::kScanFile)) load_bus_scans(dir + "/" + bus_recording::kScanFile);
  if (exists(dir + "/" + bus_recording::kReceiversFile))
    load_receivers(dir + "/" + bus_recording::kReceiversFile);
  if (exists(dir + "/" + bus_recording::kTruthFile)) load_bus_truth(dir + "/" + bus_recording::kTruthFile);
}

void ReplaySource::load_bus_odometry(const std::string& path) {
  CsvReader csv = open(path, {"stamp_ns", "wheel_velocity_right_mps", "wheel_velocity_left_mps",
                              "wheel_base_m", "var_right", "cov_right_left", "var_left"});
  while (csv.next()) {
    std::int64_t stamp = 0;
    double right = 0, left = 0, base = 0, var_right = 0, cov = 0, var_left = 0;
    if (!complete(csv, "odometry") || !take_integer(csv, "odometry", "stamp_ns", stamp, 0, kMaxStampNs) ||
        !take(csv, "odometry", "wheel_velocity_right_mps", right, -kAnyFinite, kAnyFinite) ||
        !take(csv, "odometry", "wheel_velocity_left_mps", left, -kAnyFinite, kAnyFinite) ||
        !take(csv, "odometry", "wheel_base_m", base, -kAnyFinite, kAnyFinite) ||
        !take(csv, "odometry", "var_right", var_right, -kAnyFinite, kAnyFinite) ||
        !take(csv, "odometry", "cov_right_left", cov, -kAnyFinite, kAnyFinite) ||
        !take(csv, "odometry", "var_left", var_left, -kAnyFinite, kAnyFinite)) {
      continue;
    }
    SourceEvent e;
    e.kind = SourceEvent::Kind::kOdometry;
    e.stamp_ns = stamp;
    e.odometry.stamp_ns = stamp;
    e.odometry.wheel_velocity_right_mps = right;
    e.odometry.wheel_velocity_left_mps = left;
    e.odometry.wheel_base_m = base;
    e.odometry.wheel_velocity_covariance << var_right, cov, cov, var_left;
    events_.push_back(e);
  }
}

void ReplaySource::load_bus_tofs(const std::string& path) {
  CsvReader csv = open(path, {"fire_stamp_ns", "beacon_id", "receiver_id", "tof_s", "beacon_temperature_c",
                              "sequence_number"});
  while (csv.next()) {
    std::int64_t fire = 0, beacon = 0, receiver = 0, sequence = 0;
    double tof = 0, temperature = 0;
    if (!complete(csv, "tof") || !take_integer(csv, "tof", "fire_stamp_ns", fire, 0, kMaxStampNs) ||
        !take_integer(csv, "tof", "beacon_id", beacon, 0, kMaxId) ||
        !take_integer(csv, "tof", "receiver_id", receiver, 0, kMaxId) ||
        !take(csv, "tof", "tof_s", tof, -kMaxRecordedTofS, kMaxRecordedTofS) ||
        !take(csv, "tof", "beacon_temperature_c", temperature, -kAnyFinite, kAnyFinite) ||
        !take_integer(csv, "tof", "sequence_number", sequence, 0, kMaxSequence)) {
      continue;
    }
    SourceEvent e;
    e.kind = SourceEvent::Kind::kTof;
    e.tof.fire_stamp_ns = fire;
    e.tof.beacon_id = static_cast<std::uint32_t>(beacon);
    e.tof.receiver_id = static_cast<std::uint32_t>(receiver);
    e.tof.tof_s = tof;
    e.tof.beacon_temperature_c = temperature;
    e.tof.sequence_number = static_cast<std::uint64_t>(sequence);
    e.stamp_ns = fire + s_to_ns(tof);  // the pulse's arrival, as the simulator stamps it
    if (csv.has_column("true_beacon_id")) {
      std::int64_t truth = 0;
      std::string ignored;
      if (csv.read("true_beacon_id", truth, 0, kMaxId, ignored) == NumberError::kNone) {
        e.true_beacon_id = static_cast<std::uint32_t>(truth);
      }
    }
    events_.push_back(e);
  }
}

void ReplaySource::load_bus_pulses(const std::string& path) {
  beacon_input_ = BeaconInput::kPulseArrivals;
  CsvReader csv = open(path, {"stamp_ns", "receiver_id", "mark", "sequence_number"});
  while (csv.next()) {
    std::int64_t stamp = 0, receiver = 0, sequence = 0;
    if (!complete(csv, "pulse") || !take_integer(csv, "pulse", "stamp_ns", stamp, 0, kMaxStampNs) ||
        !take_integer(csv, "pulse", "receiver_id", receiver, 0, kMaxId) ||
        !take_integer(csv, "pulse", "sequence_number", sequence, 0, kMaxSequence)) {
      continue;
    }
    const std::string& mark = csv.cell("mark");
    const std::optional<PulseMark> parsed = bus_recording::parse_pulse_mark(mark);
    if (!parsed) {
      refuse("pulse", csv.line(), "invalid_mark", "mark '" + mark + "' is not single, double or not_reported");
      continue;
    }
    SourceEvent e;
    e.kind = SourceEvent::Kind::kPulse;
    e.stamp_ns = stamp;
    e.pulse.stamp_ns = stamp;
    e.pulse.receiver_id = static_cast<std::uint32_t>(receiver);
    e.pulse.mark = *parsed;
    e.pulse.sequence_number = static_cast<std::uint64_t>(sequence);
    events_.push_back(e);
  }
}

void ReplaySource::load_bus_scans(const std::string& path) {
  CsvReader csv = open(
      path, {"stamp_ns", "angle_min_rad", "angle_increment_rad", "range_min_m", "range_max_m", "ranges_m"});
  while (csv.next()) {
    std::int64_t stamp = 0;
    if (!complete(csv, "scan") || !take_integer(csv, "scan", "stamp_ns", stamp, 0, kMaxStampNs)) continue;
    SourceEvent e;
    e.kind = SourceEvent::Kind::kLaserScan;
    e.stamp_ns = stamp;
    e.scan.stamp_ns = stamp;
    bool ok = true;
    for (auto [column, field] :
         {std::pair{"angle_min_rad", &e.scan.angle_min_rad},
          std::pair{"angle_increment_rad", &e.scan.angle_increment_rad},
          std::pair{"range_min_m", &e.scan.range_min_m}, std::pair{"range_max_m", &e.scan.range_max_m}}) {
      if (ok && parse_beam(csv.cell(column), *field) != NumberError::kNone) {
        refuse("scan", csv.line(), "malformed_row",
               std::string(column) + " '" + csv.cell(column) + "' is no float");
        ok = false;
      }
    }
    std::istringstream beams(csv.cell("ranges_m"));
    std::string beam;
    while (ok && std::getline(beams, beam, ' ')) {
      float range = 0.0f;
      if (parse_beam(beam, range) != NumberError::kNone) {
        refuse("scan", csv.line(), "malformed_row", "beam '" + beam + "' is no float");
        ok = false;
      }
      e.scan.ranges_m.push_back(range);
    }
    if (ok) events_.push_back(e);
  }
}

void ReplaySource::load_bus_truth(const std::string& path) {
  CsvReader csv = open(path, {"stamp_ns", "x_m", "y_m", "yaw_rad"});
  while (csv.next()) {
    std::int64_t stamp = 0;
    double x = 0, y = 0, yaw = 0;
    const bool has_yaw = csv.complete() && !csv.cell("yaw_rad").empty();
    if (!complete(csv, "truth") || !take_integer(csv, "truth", "stamp_ns", stamp, 0, kMaxStampNs) ||
        !take(csv, "truth", "x_m", x, -kMaxMapCoordinateM, kMaxMapCoordinateM) ||
        !take(csv, "truth", "y_m", y, -kMaxMapCoordinateM, kMaxMapCoordinateM) ||
        (has_yaw && !take(csv, "truth", "yaw_rad", yaw, -kMaxAngleRad, kMaxAngleRad))) {
      continue;
    }
    SourceEvent e;
    e.kind = SourceEvent::Kind::kTruth;
    e.stamp_ns = stamp;
    e.has_truth = true;
    e.truth_map_base = {x, y, wrap_angle_rad(yaw)};
    e.truth_has_yaw = has_yaw;
    truth_has_yaw_ = truth_has_yaw_ || has_yaw;
    events_.push_back(e);
  }
}

void ReplaySource::load_receivers(const std::string& path) {
  // The robot's geometry: a bad row refuses the recording, as a bad beacon row does.
  CsvReader csv = open(path, {"receiver_id", "x_m", "y_m", "height_m"});
  ReceiverArray receivers;
  while (csv.next()) {
    std::int64_t id = 0;
    double x = 0, y = 0, height = 0;
    std::string problem;
    if (!csv.complete() || csv.read("receiver_id", id, 0, kMaxId, problem) != NumberError::kNone ||
        csv.read("x_m", x, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone ||
        csv.read("y_m", y, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) != NumberError::kNone ||
        csv.read("height_m", height, -kMaxMapCoordinateM, kMaxMapCoordinateM, problem) !=
            NumberError::kNone) {
      throw ReplayError(csv.where() + ": malformed receiver row " +
                        (csv.complete() ? problem : csv.cell_count_problem()));
    }
    if (id != static_cast<std::int64_t>(receivers.size())) {
      throw ReplayError(csv.where() + ": receiver " + std::to_string(id) + " where " +
                        std::to_string(receivers.size()) + " comes next (ids 0, 1, ... in order)");
    }
    receivers.receivers_base_m.emplace_back(x, y);
    receivers.receiver_height_m = height;
  }
  if (receivers.size() == 0) throw ReplayError(path + ": no receivers");
  receivers_ = receivers;
}

}  // namespace beaconloc
