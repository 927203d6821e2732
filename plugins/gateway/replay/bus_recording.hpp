#pragma once
// A recording of what the bus carried for one robot (docs/replay-format.md, "Recordings of the
// bus"): the gateway's samples as it published them (tof.csv or pulse.csv, odometry.csv, scan.csv),
// the beacon map (beacons.csv), the receivers when known (receivers.csv) and, from a simulator,
// the truth (truth.csv). Written by the gateway (run --out) and by `beaconloc record`; read back
// by ReplaySource, which publishes the very samples recorded: every number is written in the
// shortest form that reads back to the same double (std::to_chars), and every row with one
// write(2), so that a recording cut by a kill ends with a whole row. DDS-free.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/receiver_array.hpp"

namespace beaconloc {

namespace bus_recording {
inline constexpr const char* kTofFile = "tof.csv";
inline constexpr const char* kPulseFile = "pulse.csv";
inline constexpr const char* kOdometryFile = "odometry.csv";
inline constexpr const char* kScanFile = "scan.csv";
inline constexpr const char* kBeaconsFile = "beacons.csv";
inline constexpr const char* kReceiversFile = "receivers.csv";
inline constexpr const char* kTruthFile = "truth.csv";

inline constexpr const char* kTofHeader =
    "fire_stamp_ns,beacon_id,receiver_id,tof_s,beacon_temperature_c,sequence_number";
inline constexpr const char* kPulseHeader = "stamp_ns,receiver_id,mark,sequence_number";
inline constexpr const char* kOdometryHeader =
    "stamp_ns,wheel_velocity_right_mps,wheel_velocity_left_mps,wheel_base_m,var_right,cov_right_left,var_"
    "left";
// ranges_m: the beams' ranges separated by spaces; a beam without a return may be inf or nan, as
// on the bus (LaserScan carries them; the localizer counts them).
inline constexpr const char* kScanHeader =
    "stamp_ns,angle_min_rad,angle_increment_rad,range_min_m,range_max_m,ranges_m";
inline constexpr const char* kReceiversHeader = "receiver_id,x_m,y_m,height_m";
inline constexpr const char* kTruthHeader = "stamp_ns,x_m,y_m,yaw_rad";
// The simulator's hidden truth about a TOF or pulse (who fired; an echo or not), for evaluation
// only: extra columns a replay ignores.
inline constexpr const char* kHiddenTruthColumns = ",true_beacon_id,echo";

// A pulse's mark as recordings write it (to_string(PulseMark): pulse.csv here, pulses.csv of the
// dataset layout), read back; nullopt for any other text.
inline std::optional<PulseMark> parse_pulse_mark(std::string_view name) {
  for (const PulseMark m : {PulseMark::kNotReported, PulseMark::kSingle, PulseMark::kDouble}) {
    if (name == to_string(m)) return m;
  }
  return std::nullopt;
}
}  // namespace bus_recording

// A file written one whole line per write(2) (O_APPEND): a kill leaves whole lines only. Throws
// std::runtime_error naming the file when it cannot be created or written.
class LineFile {
 public:
  LineFile() = default;
  LineFile(const std::string& path, std::string_view header);
  LineFile(LineFile&& other) noexcept;
  LineFile& operator=(LineFile&& other) noexcept;
  LineFile(const LineFile&) = delete;
  LineFile& operator=(const LineFile&) = delete;
  ~LineFile();
  bool is_open() const { return fd_ >= 0; }
  // line without its '\n'.
  void write_line(std::string line);

 private:
  std::string path_;
  int fd_ = -1;
};

// What the simulator knows of a TOF or pulse and the bus does not carry.
struct HiddenTruth {
  std::uint32_t true_beacon_id = kBeaconUnidentified;
  bool echo = false;
};

// Writes a recording of the bus into a directory (created if missing). Each file is made with its
// first sample, so that a recording has tof.csv or pulse.csv as its robot heard its beacons.
// Not thread-safe: one writer per thread, or the caller's lock.
class BusRecordingWriter {
 public:
  // with_hidden_truth: the simulator's gateway, which adds kHiddenTruthColumns to tof and pulse rows.
  BusRecordingWriter(std::string directory, bool with_hidden_truth);
  const std::string& directory() const { return directory_; }
  void write(const RawTofSample& t, const HiddenTruth& truth = {});
  void write(const PulseArrivalSample& p, const HiddenTruth& truth = {});
  void write(const OdometrySample& o);
  void write(const LaserScanSample& s);
  // Whole files, written once (a changed map is written again, replacing the file).
  void write_beacons(const BeaconMap& map) const;
  void write_receivers(const ReceiverArray& receivers) const;

 private:
  std::string path(const char* file) const { return directory_ + "/" + file; }
  std::string directory_;
  bool with_hidden_truth_;
  LineFile tof_, pulse_, odometry_, scan_;
};

}  // namespace beaconloc
