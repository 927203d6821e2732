#pragma once
// Replays a recording in the common CSV layout of ../shared/datasets/*/replay/ (documented in
// docs/replay-format.md): odom.csv (t_s, dt_s, v_mps, omega_radps), ranges.csv (t_s, beacon_id,
// range_m), beacons.csv (beacon_id, x_m, y_m, z_m), optional gt.csv (t_s, x_m, y_m[, yaw_rad]);
// from beacons without a radio message (seed 002), pulses.csv (t_s, mark) instead of ranges.csv.
// Extra columns are allowed and ignored. A malformed, out-of-range, duplicate or out-of-order row
// is skipped and counted by reason (reported with its file and line): "<file>.malformed_row" (a
// cell short, a cell not a decimal number), "<file>.invalid_<column>" (a number outside its
// column's range: stamps in [0, kMaxFileStampS], wheel speeds within kMaxWheelSpeedMps, ...,
// core/limits.hpp), "<file>.duplicate_row" (a second range to a beacon at a stamp, a second
// odometry interval or truth row at a stamp), "<file>.out_of_order_row". A missing file or header is
// an error.
// Ranges filed out of stamp order are replayed in stamp order (and said in load_notes()).
// A directory holding odometry.csv is instead a recording of the bus (bus_recording.hpp): the
// samples are replayed as they were published, numbers and all, for the decoder and the
// localizer to judge again.
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/rejection_counter.hpp"
#include "source.hpp"

namespace beaconloc {

class ReplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ReplayOptions {
  // Beyond these the noise says nothing (a wheel speed sigma of 1 m/s at 1 m/s over 1 s; a
  // heading sigma of 1 rad after 1 s): refused.
  static constexpr double kMaxOdometryKvM = 1.0;
  static constexpr double kMaxHeadingArwRadPerSqrtS = 1.0;
  // The recording gives (v, omega); the Odometry topic carries wheel velocities. Any wheel base
  // converts exactly; a half_track_m column, when present, gives the robot's own.
  double wheel_base_m = 0.5;
  // Odometry noise reported with each sample: recordings carry none. Distance: seed 000's model,
  // sigma^2 = k_v |v| / dT, per wheel when the recording gives the robot's own wheels
  // (half_track_m), else on the speed v.
  double odometry_k_v_m = 4e-4;
  // Heading, for a recording without wheels (its omega from whatever the robot measured it
  // with): white rate noise, sigma_omega^2 = N^2 / dT, N the heading sensor's angle random walk
  // in rad/sqrt(s). The default is the value the CMU Plaza recordings (the one such vehicle we
  // have) fit best without ground truth: the smallest mean range_innovation_nll_nats of
  // range_ekf over both (scripts/replay-noise-fit.sh, docs/replay-odometry-noise.md). With
  // wheels, the heading noise follows from theirs.
  double odometry_heading_arw_rad_per_sqrt_s = 0.014;
  // Ranges travel as TOF: tof = range / c(T), with this temperature reported alongside, so the
  // decoder recovers each range exactly.
  double reference_temperature_c = 20.0;
};

class ReplaySource final : public Source {
 public:
  ReplaySource(const std::string& directory, ReplayOptions options = {});
  void advance(StampNs until_ns, std::vector<SourceEvent>& out) override;
  bool exhausted() const override { return next_ >= events_.size(); }
  bool finite() const override { return true; }
  BeaconMap beacon_map() const override { return map_; }
  ReceiverArray receivers() const override { return receivers_; }
  StampNs first_stamp_ns() const override { return events_.empty() ? 0 : events_.front().stamp_ns; }
  StampNs last_stamp_ns() const override { return events_.empty() ? 0 : events_.back().stamp_ns; }
  bool relative_stamps() const override { return false; }
  std::string describe() const override { return "replay " + directory_; }
  BeaconInput beacon_input() const override { return beacon_input_; }
  RejectionCounter input_rejections() const override { return load_counts_; }

  // Rows refused while loading, by reason (e.g. "odom.malformed_row"), and the first problems
  // with file and line.
  const RejectionCounter& load_counts() const { return load_counts_; }
  const std::vector<std::string>& load_problems() const { return problems_; }
  // Things worth saying that refuse nothing (ranges filed out of stamp order).
  const std::vector<std::string>& load_notes() const { return notes_; }
  std::size_t event_count() const { return events_.size(); }
  bool has_truth_yaw() const { return truth_has_yaw_; }

 private:
  void load_beacons(const std::string& path);
  // A dataset (odom.csv, ranges.csv or pulses.csv, gt.csv): rows of (v, omega), ranges, pulses.
  void load_dataset();
  void load_odometry(const std::string& path);
  // The wheel speeds' covariance reported with a row of (v, omega) held over dt_s, its wheels
  // half_track_m from the middle (ReplayOptions: the noise models).
  Eigen::Matrix2d odometry_covariance(bool own_wheels, const Eigen::Vector2d& wheels_mps, double v_mps, double dt_s,
                                      double half_track_m) const;
  void load_ranges(const std::string& path);
  void load_pulses(const std::string& path);
  void load_truth(const std::string& path);
  // A recording of the bus (bus_recording.hpp; replay_bus_recording.cpp): the samples as published.
  void load_bus_recording();
  void load_bus_odometry(const std::string& path);
  void load_bus_tofs(const std::string& path);
  void load_bus_pulses(const std::string& path);
  void load_bus_scans(const std::string& path);
  void load_bus_truth(const std::string& path);
  void load_receivers(const std::string& path);
  // The current row's integer `column` within [min, max]; else refused like take().
  bool take_integer(const CsvReader& csv, const std::string& file, const std::string& column, std::int64_t& out,
                    std::int64_t min, std::int64_t max);
  static CsvReader open(const std::string& path, const std::vector<std::string>& columns);
  // The current row has every cell; else refused as <file>.malformed_row.
  bool complete(const CsvReader& csv, const std::string& file);
  // The row's `column` within [min, max]; else the row is refused (malformed_row when the cell is
  // not a number, invalid_<column> when it lies outside) and false returned.
  bool take(const CsvReader& csv, const std::string& file, const std::string& column, double& out, double min,
            double max);
  // Notes (load_notes) a row of `file` stamped before the row before it.
  void note_if_earlier(const std::string& file, std::size_t line, StampNs previous_ns, StampNs stamp_ns);
  void refuse(const std::string& file, std::size_t line, const std::string& reason,
              const std::string& detail);

  std::string directory_;
  ReplayOptions options_;
  BeaconMap map_;
  ReceiverArray receivers_ = single_receiver();
  static ReceiverArray single_receiver();
  std::vector<SourceEvent> events_;
  std::size_t next_ = 0;
  bool truth_has_yaw_ = false;
  BeaconInput beacon_input_ = BeaconInput::kRawTof;
  RejectionCounter load_counts_;
  std::vector<std::string> problems_;
  std::vector<std::string> notes_;
};

}  // namespace beaconloc
