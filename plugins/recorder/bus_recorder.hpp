#pragma once
// beaconloc record, the bus side: one robot's samples as the gateway published them (RawTof or
// PulseArrival, Odometry, LaserScan), the beacon map and the poses the localizers published, into
// a recording of the bus (replay/bus_recording.hpp) that `beaconloc run --replay DIR` replays, and
// estimate.csv (every pose heard, corrections included) that `beaconloc eval` scores. Each row is
// written as it arrives, whole: a recorder killed mid-run leaves a recording valid to its last row.
// A sample of another robot is not this recording's; one that does not convert (a beacon map that
// check_beacons refuses) is counted, not written.
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/receiver_array.hpp"
#include "beaconloc/dds/participant.hpp"
#include "replay/bus_recording.hpp"

namespace beaconloc {

struct BusRecorderOptions {
  std::string out_dir;
  std::string robot_id = "robot1";
  // The robot's receivers, written as receivers.csv for the replay; the bus does not carry them.
  std::optional<ReceiverArray> receivers;
};

class BusRecorder {
 public:
  BusRecorder(const dds::DdsOptions& dds, BusRecorderOptions options);
  // Rows written, by file ("tof.csv", ...), and samples refused, by reason.
  std::map<std::string, std::uint64_t> written() const;
  std::map<std::string, std::uint64_t> refused() const;
  std::uint64_t samples_written() const;  // measurements: TOFs, pulses, odometry, scans

 private:
  template <class Write>
  void record(const char* file, Write&& write);
  void on_beacon_map(const BeaconMap& map);

  BusRecorderOptions options_;
  dds::Participant participant_;  // first: a participant that cannot start leaves no file behind
  mutable std::mutex mutex_;
  BusRecordingWriter writer_;
  LineFile estimates_;
  std::optional<BeaconMap> map_;  // the newest written
  std::map<std::string, std::uint64_t> written_;
  std::map<std::string, std::uint64_t> refused_;
  std::atomic<std::uint64_t> samples_{0};
  dds::Reader tof_reader_, pulse_reader_, odometry_reader_, scan_reader_, map_reader_, pose_reader_;  // last
};

}  // namespace beaconloc
