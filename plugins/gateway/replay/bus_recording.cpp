#include "bus_recording.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/decimal.hpp"

namespace beaconloc {
namespace {

void append_integer(std::string& out, std::int64_t value) {
  std::array<char, 24> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), end);
}

void append_unsigned(std::string& out, std::uint64_t value) {
  std::array<char, 24> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), end);
}

// A scan's beam: finite as a number, else the word the bus's float was (inf, -inf, nan).
void append_beam(std::string& out, float range_m) {
  if (std::isnan(range_m)) {
    out += "nan";
  } else if (std::isinf(range_m)) {
    out += range_m > 0 ? "inf" : "-inf";
  } else {
    append_decimal(out, static_cast<double>(range_m));  // a float is exactly a double
  }
}

void append_hidden_truth(std::string& line, const HiddenTruth& truth) {
  line += ',';
  append_unsigned(line, truth.true_beacon_id);
  line += truth.echo ? ",1" : ",0";
}

}  // namespace

LineFile::LineFile(const std::string& path, std::string_view header) : path_(path) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
  write_line(std::string(header));
}

LineFile::LineFile(LineFile&& other) noexcept { *this = std::move(other); }

LineFile& LineFile::operator=(LineFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

LineFile::~LineFile() {
  if (fd_ >= 0) ::close(fd_);
}

void LineFile::write_line(std::string line) {
  line += '\n';
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("writing '" + path_ + "' failed: " + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
}

BusRecordingWriter::BusRecordingWriter(std::string directory, bool with_hidden_truth)
    : directory_(std::move(directory)), with_hidden_truth_(with_hidden_truth) {
  std::error_code ec;
  std::filesystem::create_directories(directory_, ec);
  if (ec) throw std::runtime_error("cannot create '" + directory_ + "': " + ec.message());
  // Files are made with their first sample: an earlier recording's in the same directory (a
  // scan.csv this run will not write) must not be replayed with this one.
  for (const char* file : {bus_recording::kTofFile, bus_recording::kPulseFile, bus_recording::kOdometryFile,
                           bus_recording::kScanFile, bus_recording::kReceiversFile, bus_recording::kBeaconsFile}) {
    std::filesystem::remove(path(file), ec);
    if (ec) throw std::runtime_error("cannot remove the earlier '" + path(file) + "': " + ec.message());
  }
}

void BusRecordingWriter::write(const RawTofSample& t, const HiddenTruth& truth) {
  if (!tof_.is_open()) {
    tof_ = LineFile(path(bus_recording::kTofFile),
                    std::string(bus_recording::kTofHeader) +
                        (with_hidden_truth_ ? bus_recording::kHiddenTruthColumns : ""));
  }
  std::string line;
  append_integer(line, t.fire_stamp_ns);
  line += ',';
  append_unsigned(line, t.beacon_id);
  line += ',';
  append_unsigned(line, t.receiver_id);
  line += ',';
  append_decimal(line, t.tof_s);
  line += ',';
  append_decimal(line, t.beacon_temperature_c);
  line += ',';
  append_unsigned(line, t.sequence_number);
  if (with_hidden_truth_) append_hidden_truth(line, truth);
  tof_.write_line(std::move(line));
}

void BusRecordingWriter::write(const PulseArrivalSample& p, const HiddenTruth& truth) {
  if (!pulse_.is_open()) {
    pulse_ = LineFile(path(bus_recording::kPulseFile),
                      std::string(bus_recording::kPulseHeader) +
                          (with_hidden_truth_ ? bus_recording::kHiddenTruthColumns : ""));
  }
  std::string line;
  append_integer(line, p.stamp_ns);
  line += ',';
  append_unsigned(line, p.receiver_id);
  line += ',';
  line += to_string(p.mark);
  line += ',';
  append_unsigned(line, p.sequence_number);
  if (with_hidden_truth_) append_hidden_truth(line, truth);
  pulse_.write_line(std::move(line));
}

void BusRecordingWriter::write(const OdometrySample& o) {
  if (!odometry_.is_open())
    odometry_ = LineFile(path(bus_recording::kOdometryFile), bus_recording::kOdometryHeader);
  std::string line;
  append_integer(line, o.stamp_ns);
  for (double v : {o.wheel_velocity_right_mps, o.wheel_velocity_left_mps, o.wheel_base_m,
                   o.wheel_velocity_covariance(0, 0), o.wheel_velocity_covariance(0, 1),
                   o.wheel_velocity_covariance(1, 1)}) {
    line += ',';
    append_decimal(line, v);
  }
  odometry_.write_line(std::move(line));
}

void BusRecordingWriter::write(const LaserScanSample& s) {
  if (!scan_.is_open()) scan_ = LineFile(path(bus_recording::kScanFile), bus_recording::kScanHeader);
  std::string line;
  append_integer(line, s.stamp_ns);
  for (float v : {s.angle_min_rad, s.angle_increment_rad, s.range_min_m, s.range_max_m}) {
    line += ',';
    append_beam(line, v);
  }
  line += ',';
  for (std::size_t i = 0; i < s.ranges_m.size(); ++i) {
    if (i) line += ' ';
    append_beam(line, s.ranges_m[i]);
  }
  scan_.write_line(std::move(line));
}

void BusRecordingWriter::write_beacons(const BeaconMap& map) const {
  write_beacon_map_csv(path(bus_recording::kBeaconsFile), map);
}

void BusRecordingWriter::write_receivers(const ReceiverArray& receivers) const {
  std::string text = std::string(bus_recording::kReceiversHeader) + '\n';
  for (std::size_t i = 0; i < receivers.size(); ++i) {
    append_unsigned(text, i);
    text += ',';
    append_decimal(text, receivers.receivers_base_m[i].x());
    text += ',';
    append_decimal(text, receivers.receivers_base_m[i].y());
    text += ',';
    append_decimal(text, receivers.receiver_height_m);
    text += '\n';
  }
  write_file_atomically(path(bus_recording::kReceiversFile), text);
}

}  // namespace beaconloc
