#pragma once
// The ROS 2 bridge: a Fast DDS participant speaking ROS 2 on the wire (rt/ topics, ROS 2 type
// names, QoS of examples/qos/ros2_topics.xml). No ROS 2 code: the types are IDL (idl/ros2).
//  out: beacon_pose, odometry/beacons, tf (map -> odom), tf_static (receiver frames), beacons
//       (MarkerArray of the beacon map), beacon_ranges (sensor_msgs/Range per accepted range);
//  graph: the node beaconloc_bridge_<robot> on ros_discovery_info, for ROS 2 tools (ros_graph.hpp);
//  in:  odom (nav_msgs/Odometry) and scan (sensor_msgs/LaserScan) from a ROS 2 robot's drivers,
//       republished as the project's Odometry and LaserScan; initialpose (rviz2's 2D Pose
//       Estimate, Nav2) as the project's InitialPose, which restarts the localizer there.
#include <beaconloc.h>

#include <atomic>
#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/receiver_array.hpp"
#include "beaconloc/core/rejection_counter.hpp"
#include "beaconloc/dds/diagnostics_publisher.hpp"
#include "beaconloc/dds/first_sample_watch.hpp"
#include "beaconloc/dds/participant.hpp"
#include "odom_frame.hpp"
#include "pending_transforms.hpp"
#include "ros2_types.hpp"

namespace beaconloc::bridge {

struct BridgeOptions {
  std::string robot_id = "robot1";  // whose pose estimate and odometry go to this namespace
  std::string ros_namespace;        // "" or e.g. "robot1": rt/<ns>/beacon_pose
  std::string map_frame = "map";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  ReceiverArray receivers;  // for tf_static and the frames of beacon_ranges
  // In: a ROS 2 robot's drivers feed the localizer. Off when the gateway gives the odometry.
  bool odometry_in = false;
  bool scan_in = false;
  double wheel_base_m = 0.33;               // to express a driver's (v, omega) as wheel velocities
  float range_field_of_view_rad = 2.0944f;  // 120 degrees: the receivers' cone (assumption)
  float range_min_m = 0.0f;
  float range_max_m = 15.0f;
  // Beacons to draw when no gateway publishes the beacon map (a ROS 2 robot's own drivers feed
  // us): published once as rt/<ns>/beacons.
  std::optional<BeaconMap> beacons;
};

// rt/<ns>/<name>, or rt/<name> without a namespace (ROS 2 topic naming, ROS2-INTEROP.md).
std::string ros_topic(const std::string& ros_namespace, const std::string& name);

class BridgeParticipant {
 public:
  BridgeParticipant(const dds::DdsOptions& dds, BridgeOptions options);
  const RejectionCounter& counts() const { return counts_; }

 private:
  void on_pose(const msg::PoseEstimate& m);
  void on_odometry(const msg::Odometry& m);
  void on_beacon_map(const msg::BeaconMap& m);
  void on_range(const msg::BeaconRange& m);
  void on_ros_odometry(const nav_msgs::msg::Odometry& m);
  void on_ros_scan(const sensor_msgs::msg::LaserScan& m);
  void on_ros_initial_pose(const geometry_msgs::msg::PoseWithCovarianceStamped& m);
  void publish_static_frames();
  // map -> odom for the poses whose odometry has arrived (a pose can overtake its odometry).
  void publish_pending_transforms();
  msg::Diagnostics diagnostics_snapshot();

  BridgeOptions options_;
  // The bridge's state. Never held while writing to the pipeline's own topics (the localizer's
  // inputs: odometry, scans, initial poses): the localizer publishes poses under its lock and,
  // in one process (`run --bridge`), a pose reaches on_pose within that write. Holding mutex_
  // there took the two locks in opposite orders: the run deadlocked at a 2D Pose Estimate.
  std::mutex mutex_;
  // Orders those writes (each stream's samples go out in the order they were made); taken
  // before mutex_, never while holding it.
  std::mutex pipeline_writes_mutex_;
  OdomFrame odom_;
  PendingTransforms pending_transforms_;  // poses newer than the odometry received so far
  RejectionCounter counts_;
  // When the robot's last pose arrived: a bridge whose localizer stopped says so (a pose every
  // 10 ms is the rate; kPoseSilentAfter is 200 of them).
  static constexpr std::chrono::seconds kPoseSilentAfter{2};
  std::optional<std::chrono::steady_clock::time_point> last_pose_received_;
  std::uint64_t odometry_sequence_ = 0;
  // Topic names live here: the TopicSpecs point into them.
  std::string beacon_pose_topic_, odometry_out_topic_, beacons_topic_, ranges_topic_, odom_in_topic_,
      scan_in_topic_, initial_pose_topic_;
  dds::Participant participant_;
  dds::Writer beacon_pose_writer_;
  dds::Writer odometry_out_writer_;
  dds::Writer tf_writer_;
  dds::Writer tf_static_writer_;
  dds::Writer beacons_writer_;
  dds::Writer ranges_writer_;
  dds::Writer odometry_in_writer_;
  dds::Writer scan_in_writer_;
  dds::Writer initial_pose_writer_;
  dds::Writer ros_discovery_info_writer_;  // the node and its endpoints in the ROS 2 graph
  // Before diagnostics_, which reports its count: it goes after the Diagnostics task stops.
  std::unique_ptr<dds::FirstSampleWatch> map_reader_;  // recreated when mute (first_sample_watch.hpp)
  std::unique_ptr<dds::DiagnosticsPublisher> diagnostics_;
  std::vector<dds::Reader> readers_;  // last: they stop before what their callbacks use goes
};

}  // namespace beaconloc::bridge
