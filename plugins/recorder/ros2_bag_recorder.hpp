#pragma once
// beaconloc record, the ROS 2 side: the topics a bridge speaks in one ROS 2 namespace (its
// outputs beacon_pose, odometry/beacons, tf, tf_static, beacons, beacon_ranges; its inputs odom,
// scan, initialpose), each message exactly as it travelled (its CDR bytes), into a rosbag2 bag
// (sqlite3 storage, rosbag2/rosbag2_writer.hpp) that `ros2 bag info` and `ros2 bag play` open.
// A message that does not read as its type is refused and counted (the participant's
// undecodable_samples), never written. Stamped with the wall time it arrived, as rosbag2 records.
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "beaconloc/dds/participant.hpp"
#include "rosbag2_writer.hpp"

namespace beaconloc {

struct Ros2BagOptions {
  std::string bag_dir;        // must not exist yet
  std::string ros_namespace;  // "" or e.g. "robot1", as the bridge's --namespace
};

class Ros2BagRecorder {
 public:
  Ros2BagRecorder(const dds::DdsOptions& dds, Ros2BagOptions options);
  ~Ros2BagRecorder();
  // Messages written, by ROS 2 topic name ("/beacon_pose").
  std::map<std::string, std::uint64_t> written() const;
  std::uint64_t undecodable() const { return participant_.undecodable_samples(); }
  std::uint64_t failed_writes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return failed_writes_;
  }
  // Writes the bag's metadata and closes it; nothing is recorded after.
  void close();

 private:
  template <class PubSubType>
  void add(const std::string& name, const char* ros_type, const char* reader_profile,
           rosbag2::TopicQos offered);

  Ros2BagOptions options_;
  dds::Participant participant_;  // first: a participant that cannot start leaves no bag behind
  mutable std::mutex mutex_;
  rosbag2::Rosbag2Writer bag_;
  bool closed_ = false;
  std::map<std::string, std::uint64_t> written_;
  std::uint64_t failed_writes_ = 0;
  std::vector<dds::Reader> readers_;  // last: stop before what they use goes
};

}  // namespace beaconloc
