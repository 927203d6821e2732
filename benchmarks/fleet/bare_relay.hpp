#pragma once
// The fleet benchmark's yardstick (--bare): what Fast DDS alone costs for the localizer's sample
// rates. It takes the place of the localizer with the same participant profile, the same readers
// (odometry, beacon_range) and the same pose writer, and writes a pose for every odometry sample
// (at its stamp) and one for every range (a correction, at the robot's newest odometry stamp, as
// the localizer's are): the same samples in and out, with no estimator, no input checks and no
// deadline watch. Answers the measurement loop's questions as LocalizerParticipant does.
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include "beaconloc/core/time.hpp"
#include "beaconloc/dds/participant.hpp"

namespace beaconloc::bench {

class BareRelay {
 public:
  explicit BareRelay(const dds::DdsOptions& dds);
  std::uint64_t odometry_processed() const { return odometry_processed_.load(); }
  std::uint64_t poses_written() const { return poses_written_.load(); }
  StampNs newest_odometry_stamp_ns() const { return newest_odometry_stamp_ns_.load(); }
  std::uint64_t lost_increments() {
    std::lock_guard<std::mutex> lock(mutex_);
    return lost_increments_;
  }

 private:
  void write_pose(const std::string& robot_id, StampNs stamp_ns);  // under mutex_

  std::mutex mutex_;
  std::map<std::string, std::uint64_t> odometry_sequence_;  // newest sequence number per robot
  std::map<std::string, StampNs> odometry_stamp_ns_;         // newest odometry stamp per robot
  std::uint64_t lost_increments_ = 0;
  std::atomic<std::uint64_t> odometry_processed_{0};
  std::atomic<std::uint64_t> poses_written_{0};
  std::atomic<StampNs> newest_odometry_stamp_ns_{0};
  dds::Participant participant_;
  dds::Writer pose_writer_;
  dds::Reader odometry_reader_;  // readers last: they stop first
  dds::Reader range_reader_;
};

}  // namespace beaconloc::bench
