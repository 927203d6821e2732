#include "bridge_participant.hpp"

#include <beaconlocPubSubTypes.h>

#include <cctype>
#include <cmath>
#include <stdexcept>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/topics.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "ros2_convert.hpp"
#include "ros_graph.hpp"

namespace beaconloc::bridge {

std::string ros_topic(const std::string& ns, const std::string& name) {
  return ns.empty() ? "rt/" + name : "rt/" + ns + "/" + name;
}

namespace {

// A ROS 2 namespace as the bridge takes it: tokens of [A-Za-z0-9_] not starting with a digit,
// joined by '/', without leading or trailing '/' (ROS 2 name rules).
void check_namespace(const std::string& ns) {
  if (ns.empty()) return;
  bool token_start = true;
  for (char c : ns) {
    if (c == '/') {
      if (token_start) throw std::invalid_argument("bad ROS 2 namespace '" + ns + "': empty token");
      token_start = true;
      continue;
    }
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    if (!ok || (token_start && std::isdigit(static_cast<unsigned char>(c)))) {
      throw std::invalid_argument("bad ROS 2 namespace '" + ns + "' (write it without a leading '/')");
    }
    token_start = false;
  }
  if (token_start) throw std::invalid_argument("bad ROS 2 namespace '" + ns + "': ends with '/'");
}

BridgeOptions validated(BridgeOptions o) {
  check_namespace(o.ros_namespace);
  return o;
}

}  // namespace

BridgeParticipant::BridgeParticipant(const dds::DdsOptions& dds, BridgeOptions options)
    : options_(validated(std::move(options))),
      beacon_pose_topic_(ros_topic(options_.ros_namespace, "beacon_pose")),
      odometry_out_topic_(ros_topic(options_.ros_namespace, "odometry/beacons")),
      beacons_topic_(ros_topic(options_.ros_namespace, "beacons")),
      ranges_topic_(ros_topic(options_.ros_namespace, "beacon_ranges")),
      odom_in_topic_(ros_topic(options_.ros_namespace, "odom")),
      scan_in_topic_(ros_topic(options_.ros_namespace, "scan")),
      initial_pose_topic_(ros_topic(options_.ros_namespace, "initialpose")),
      participant_(dds, "beaconloc.bridge." + options_.robot_id) {
  using geometry_msgs::msg::PoseWithCovarianceStampedPubSubType;
  beacon_pose_writer_ = participant_.writer<PoseWithCovarianceStampedPubSubType>(
      {beacon_pose_topic_.c_str(), "ros2.beacon_pose.writer", ""});
  odometry_out_writer_ = participant_.writer<nav_msgs::msg::OdometryPubSubType>(
      {odometry_out_topic_.c_str(), "ros2.odometry_beacons.writer", ""});
  tf_writer_ = participant_.writer<tf2_msgs::msg::TFMessagePubSubType>({"rt/tf", "ros2.tf.writer", ""});
  tf_static_writer_ =
      participant_.writer<tf2_msgs::msg::TFMessagePubSubType>({"rt/tf_static", "ros2.tf_static.writer", ""});
  beacons_writer_ = participant_.writer<visualization_msgs::msg::MarkerArrayPubSubType>(
      {beacons_topic_.c_str(), "ros2.beacons.writer", ""});
  ranges_writer_ = participant_.writer<sensor_msgs::msg::RangePubSubType>(
      {ranges_topic_.c_str(), "ros2.beacon_ranges.writer", ""});
  std::vector<eprosima::fastrtps::rtps::GUID_t> ros_readers;  // the node's, for ros_discovery_info
  if (options_.odometry_in) {
    odometry_in_writer_ = participant_.robot_writer<msg::OdometryPubSubType>(dds::kOdometryTopic, options_.robot_id);
    readers_.push_back(participant_.subscribe<nav_msgs::msg::OdometryPubSubType>(
        {odom_in_topic_.c_str(), "", "ros2.odom.reader"},
        [this](const nav_msgs::msg::Odometry& m) { on_ros_odometry(m); }));
    ros_readers.push_back(readers_.back()->guid());
  }
  if (options_.scan_in) {
    scan_in_writer_ = participant_.robot_writer<msg::LaserScanPubSubType>(dds::kLaserScanTopic, options_.robot_id);
    readers_.push_back(participant_.subscribe<sensor_msgs::msg::LaserScanPubSubType>(
        {scan_in_topic_.c_str(), "", "ros2.scan.reader"},
        [this](const sensor_msgs::msg::LaserScan& m) { on_ros_scan(m); }));
    ros_readers.push_back(readers_.back()->guid());
  }
  initial_pose_writer_ =
      participant_.robot_writer<msg::InitialPosePubSubType>(dds::kInitialPoseTopic, options_.robot_id);
  readers_.push_back(participant_.subscribe<geometry_msgs::msg::PoseWithCovarianceStampedPubSubType>(
      {initial_pose_topic_.c_str(), "", "ros2.initialpose.reader"},
      [this](const geometry_msgs::msg::PoseWithCovarianceStamped& m) { on_ros_initial_pose(m); }));
  ros_readers.push_back(readers_.back()->guid());
  readers_.push_back(participant_.subscribe<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic,
                                                      [this](const msg::PoseEstimate& m) { on_pose(m); }));
  readers_.push_back(participant_.subscribe<msg::OdometryPubSubType>(dds::kOdometryTopic,
                                                  [this](const msg::Odometry& m) { on_odometry(m); }));
  map_reader_ = std::make_unique<dds::FirstSampleWatch>([this](std::function<void()> heard) {
    return participant_.subscribe<msg::BeaconMapPubSubType>(dds::kBeaconMapTopic, [this, heard](const msg::BeaconMap& m) {
      heard();
      on_beacon_map(m);
    });
  });
  readers_.push_back(participant_.subscribe<msg::BeaconRangePubSubType>(dds::kBeaconRangeTopic,
                                                     [this](const msg::BeaconRange& m) { on_range(m); }));
  publish_static_frames();
  if (options_.beacons) {
    auto markers = beacon_markers(*options_.beacons, options_.map_frame, dds::wall_clock_ns());
    beacons_writer_->write(&markers);
  }
  // The node in the ROS 2 graph, once all its ROS endpoints exist. Not when secured: the
  // deployment's permissions (scripts/deployment-keys.sh) do not grant ros_discovery_info yet.
  if (!participant_.secured()) {
    ros_discovery_info_writer_ = participant_.writer<rmw_dds_common::msg::ParticipantEntitiesInfoPubSubType>(
        {kRosDiscoveryInfoTopic, "ros2.ros_discovery_info.writer", ""});
    auto graph = node_entities(beacon_pose_writer_->get_publisher()->get_participant()->guid(),
                               options_.ros_namespace, ros_node_name(options_.robot_id), ros_readers,
                               {beacon_pose_writer_->guid(), odometry_out_writer_->guid(), tf_writer_->guid(),
                                tf_static_writer_->guid(), beacons_writer_->guid(), ranges_writer_->guid()});
    ros_discovery_info_writer_->write(&graph);
  }
  diagnostics_ =
      std::make_unique<dds::DiagnosticsPublisher>(participant_, [this] { return diagnostics_snapshot(); });
}

void BridgeParticipant::publish_static_frames() {
  // base_link -> receiver_<i>, all in one message (tf2's convention for /tf_static), stamped with
  // the time they are published, as static_transform_publisher stamps with now().
  const StampNs now_ns = dds::wall_clock_ns();
  tf2_msgs::msg::TFMessage frames;
  for (std::size_t i = 0; i < options_.receivers.size(); ++i) {
    const Eigen::Vector2d& r = options_.receivers.receivers_base_m[i];
    frames.transforms().push_back(to_transform(now_ns, Pose2(r.x(), r.y(), 0.0), options_.base_frame,
                                               "receiver_" + std::to_string(i),
                                               options_.receivers.receiver_height_m));
  }
  tf_static_writer_->write(&frames);
}

void BridgeParticipant::on_pose(const msg::PoseEstimate& m) {
  if (m.robot_id() != options_.robot_id) return;
  const PoseEstimate e = dds::from_msg(m);
  std::lock_guard<std::mutex> lock(mutex_);
  last_pose_received_ = std::chrono::steady_clock::now();
  if (!publishable(e)) {
    counts_.reject("pose.unusable");  // a non-finite number never reaches ROS 2
    return;
  }
  if (e.status == PoseStatus::kInitializing || e.status == PoseStatus::kLost) {
    counts_.reject("pose.not_localized");  // as amcl: no pose, no map -> odom until localized
    return;
  }
  auto pose = to_pose_with_covariance(e, options_.map_frame);
  beacon_pose_writer_->write(&pose);
  auto odometry =
      to_ros_odometry(e, odom_.v_mps(), odom_.omega_radps(), odom_.twist_covariance(), options_.map_frame,
                      options_.base_frame);
  odometry_out_writer_->write(&odometry);
  if (pending_transforms_.add(e) == PendingTransforms::Added::kQueuedDroppedOldest) {
    counts_.reject("pose.no_odometry_at_stamp");  // beacon_pose went out; map -> odom could not
  }
  publish_pending_transforms();
}

void BridgeParticipant::publish_pending_transforms() {
  const auto latest = odom_.latest_stamp_ns();
  if (!latest) return;
  for (const PoseEstimate& e : pending_transforms_.take_reached(*latest)) {
    if (const auto map_odom = odom_.pose_map_odom(e.stamp_ns, e.pose_map_base)) {
      tf2_msgs::msg::TFMessage tf;
      tf.transforms().push_back(to_transform(e.stamp_ns, *map_odom, options_.map_frame, options_.odom_frame));
      // Without a driver (--odom-in), nobody else publishes odom -> base_link: the odometry the
      // bridge integrates is the odom frame, and the tree map -> odom -> base_link -> receiver_i
      // must be whole for rviz2.
      if (!options_.odometry_in) {
        tf.transforms().push_back(to_transform(e.stamp_ns, *odom_.pose_odom_base(e.stamp_ns),
                                               options_.odom_frame, options_.base_frame));
      }
      tf_writer_->write(&tf);
      pending_transforms_.published(e.stamp_ns);
      counts_.accept();
    } else {
      counts_.reject("pose.older_than_the_odometry_history");
    }
  }
}

void BridgeParticipant::on_odometry(const msg::Odometry& m) {
  if (m.robot_id() != options_.robot_id || options_.odometry_in) return;  // the driver's pose is used then
  std::lock_guard<std::mutex> lock(mutex_);
  if (const InputResult added = odom_.add_wheel_odometry(dds::from_msg(m)); !added.accepted) {
    counts_.reject("odometry.", *added.rejection);
  }
  publish_pending_transforms();
}

void BridgeParticipant::on_beacon_map(const msg::BeaconMap& m) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::optional<BeaconMap> map = counted_beacon_map(dds::from_msg(m), counts_);
  if (!map) return;
  auto markers = beacon_markers(*map, options_.map_frame, dds::wall_clock_ns());
  beacons_writer_->write(&markers);
}

void BridgeParticipant::on_range(const msg::BeaconRange& m) {
  if (m.robot_id() != options_.robot_id) return;
  const RangeMeasurement r = dds::from_msg(m);
  std::lock_guard<std::mutex> lock(mutex_);
  if (r.receiver_id >= options_.receivers.size()) {
    counts_.reject("range.unknown_receiver");
    return;
  }
  if (!std::isfinite(r.range_m) || !(r.range_m >= 0.0) || !std::isfinite(r.variance_m2)) {
    counts_.reject("range.unusable");
    return;
  }
  auto range = to_ros_range(r, "receiver_" + std::to_string(r.receiver_id), options_.range_field_of_view_rad,
                            options_.range_min_m, options_.range_max_m);
  ranges_writer_->write(&range);
}

void BridgeParticipant::on_ros_odometry(const nav_msgs::msg::Odometry& m) {
  std::string why;
  const auto o = from_ros_odometry(m, options_.wheel_base_m, &why);
  std::lock_guard<std::mutex> order(pipeline_writes_mutex_);
  msg::Odometry out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!o) {
      counts_.reject("odom." + why);
      return;
    }
    const auto yaw = planar_yaw(m.pose().pose().orientation());
    if (!yaw || !odom_.add_odom_pose(
                    o->stamp_ns, Pose2(m.pose().pose().position().x(), m.pose().pose().position().y(), *yaw),
                    m.twist().twist().linear().x(), m.twist().twist().angular().z(),
                    ros_twist_covariance(m))) {
      counts_.reject("odom.bad_or_out_of_order_pose");
      return;
    }
    out = dds::to_msg(options_.robot_id, *o, ++odometry_sequence_);
    counts_.accept();
    publish_pending_transforms();
  }
  odometry_in_writer_->write(&out);  // not under mutex_ (see there)
}

void BridgeParticipant::on_ros_scan(const sensor_msgs::msg::LaserScan& m) {
  std::string why;
  const auto s = from_ros_scan(m, &why);
  std::lock_guard<std::mutex> order(pipeline_writes_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!s) {
      counts_.reject("scan." + why);
      return;
    }
    counts_.accept();
  }
  auto out = dds::to_msg(options_.robot_id, *s);
  scan_in_writer_->write(&out);  // not under mutex_ (see there)
}

void BridgeParticipant::on_ros_initial_pose(const geometry_msgs::msg::PoseWithCovarianceStamped& m) {
  std::string why;
  const auto init = from_initial_pose(m, &why);
  std::lock_guard<std::mutex> order(pipeline_writes_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!init) {
      counts_.reject("initialpose." + why);
      return;
    }
    if (m.header().frame_id() != options_.map_frame) {
      counts_.reject("initialpose.not_in_the_map_frame");  // no TF tree here to transform it
      return;
    }
    counts_.accept();
  }
  msg::InitialPose out;
  out.robot_id(options_.robot_id);
  out.stamp_ns(init->stamp_ns);
  out.x_m(init->pose_map_base.x());
  out.y_m(init->pose_map_base.y());
  out.yaw_rad(init->pose_map_base.z());
  for (int i = 0; i < 9; ++i) out.covariance()[static_cast<std::size_t>(i)] = init->covariance(i / 3, i % 3);
  initial_pose_writer_->write(&out);  // not under mutex_ (see there)
}

msg::Diagnostics BridgeParticipant::diagnostics_snapshot() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string message = std::string("ROS 2 ") + kRos2Distro + " layouts, robot " + options_.robot_id;
  msg::ParticipantStatus status = msg::PARTICIPANT_STATUS_OK;
  const auto now = std::chrono::steady_clock::now();
  if (!last_pose_received_) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message += "; no pose received yet";
  } else if (now - *last_pose_received_ > kPoseSilentAfter) {
    status = msg::PARTICIPANT_STATUS_DEGRADED;
    message +=
        "; no pose for " +
        std::to_string(std::chrono::duration_cast<std::chrono::seconds>(now - *last_pose_received_).count()) +
        " s: the localizer is gone or silent";
  }
  RejectionCounter counts = counts_;
  counts.reject(dds::kMapReaderRecreated, map_reader_->recreated());
  return dds::make_diagnostics(participant_.name(), dds::wall_clock_ns(), counts, 0, status, message);
}

}  // namespace beaconloc::bridge
