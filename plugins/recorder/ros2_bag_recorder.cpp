#include "ros2_bag_recorder.hpp"

#include "beaconloc/dds/wall_clock.hpp"
#include "bridge_participant.hpp"
#include "ros2_types.hpp"

namespace beaconloc {

Ros2BagRecorder::Ros2BagRecorder(const dds::DdsOptions& dds, Ros2BagOptions options)
    : options_(std::move(options)),
      participant_(dds, "beaconloc.ros2_recorder"),
      bag_(options_.bag_dir, bridge::kRos2Distro) {
  // What each topic's writers offer (examples/qos/ros2_topics.xml), so that `ros2 bag play`
  // offers it again: the bridge's outputs as the bridge writes them; a robot driver's odom and
  // scan as sensor data (best effort), rviz2's initialpose reliable.
  constexpr rosbag2::TopicQos kLatched{true, true, 1};
  add<geometry_msgs::msg::PoseWithCovarianceStampedPubSubType>("beacon_pose",
                                                               "geometry_msgs/msg/PoseWithCovarianceStamped",
                                                               "ros2.record.beacon_pose.reader", kLatched);
  add<nav_msgs::msg::OdometryPubSubType>("odometry/beacons", "nav_msgs/msg/Odometry",
                                         "ros2.record.odometry_beacons.reader", {true, false, 10});
  add<tf2_msgs::msg::TFMessagePubSubType>("/tf", "tf2_msgs/msg/TFMessage", "ros2.record.tf.reader",
                                          {true, false, 100});
  add<tf2_msgs::msg::TFMessagePubSubType>("/tf_static", "tf2_msgs/msg/TFMessage",
                                          "ros2.record.tf_static.reader", kLatched);
  add<visualization_msgs::msg::MarkerArrayPubSubType>("beacons", "visualization_msgs/msg/MarkerArray",
                                                      "ros2.record.beacons.reader", kLatched);
  add<sensor_msgs::msg::RangePubSubType>("beacon_ranges", "sensor_msgs/msg/Range",
                                         "ros2.record.beacon_ranges.reader", {true, false, 16});
  add<nav_msgs::msg::OdometryPubSubType>("odom", "nav_msgs/msg/Odometry", "ros2.odom.reader",
                                         {false, false, 10});
  add<sensor_msgs::msg::LaserScanPubSubType>("scan", "sensor_msgs/msg/LaserScan", "ros2.scan.reader",
                                             {false, false, 5});
  add<geometry_msgs::msg::PoseWithCovarianceStampedPubSubType>("initialpose",
                                                               "geometry_msgs/msg/PoseWithCovarianceStamped",
                                                               "ros2.initialpose.reader", {true, false, 1});
}

Ros2BagRecorder::~Ros2BagRecorder() {
  readers_.clear();  // no callback runs after this
  try {
    close();
  } catch (const std::exception&) {
    // The bag keeps every message written (each committed on its own); its metadata may lag.
  }
}

template <class PubSubType>
void Ros2BagRecorder::add(const std::string& name, const char* ros_type, const char* reader_profile,
                          rosbag2::TopicQos offered) {
  // /tf and /tf_static are global (tf2 does not namespace them); the others are the bridge's.
  const bool global = name.front() == '/';
  const std::string dds_name = global ? "rt" + name : bridge::ros_topic(options_.ros_namespace, name);
  const std::string ros_name = "/" + dds_name.substr(3);  // rt/ns/beacon_pose -> /ns/beacon_pose
  const int id = bag_.add_topic(ros_name, ros_type, offered);
  readers_.push_back(participant_.subscribe_raw<PubSubType>(
      {dds_name.c_str(), "", reader_profile},
      [this, id, ros_name](const dds::RawSample<PubSubType>& sample,
                           const eprosima::fastdds::dds::SampleInfo&) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (closed_) return;
        try {
          bag_.write(id, dds::wall_clock_ns(), sample.cdr.data(), sample.cdr.size());
          ++written_[ros_name];
        } catch (const rosbag2::Rosbag2Error&) {
          ++failed_writes_;  // a full disk, say: the command reports it
        }
      }));
}

std::map<std::string, std::uint64_t> Ros2BagRecorder::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}

void Ros2BagRecorder::close() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (closed_) return;
  closed_ = true;
  bag_.close();
}

}  // namespace beaconloc
