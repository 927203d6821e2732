#pragma once
// The bridge as a node of the ROS 2 graph, as rmw (rmw_fastrtps, rmw_cyclonedds) shows its own
// nodes to `ros2 node list` and `ros2 topic info -v`: `ros_discovery_info`
// (rmw_dds_common/msg/ParticipantEntitiesInfo) lists the node with the GIDs of its readers and
// writers. Without them ROS 2 tools list the bridge's topics
// under the node _CREATED_BY_BARE_DDS_APP_ and no node at all.
#include <fastdds/rtps/common/Guid.h>

#include <string>
#include <vector>

#include "ros2_types.hpp"

namespace beaconloc::bridge {

// rmw's participant USER_DATA ("enclave=/;") is set by dds::Participant before it creates the
// participant (set afterwards, DomainParticipant::set_qos, it left Fast DDS 2.9 announcing a stale
// data locator: a Cyclone DDS writer's samples never reached the bridge).
// rmw's topic of the graph (no rt/ prefix: it is not a ROS topic).
inline constexpr const char* kRosDiscoveryInfoTopic = "ros_discovery_info";

// The bridge's node name: beaconloc_bridge_<robot id>, each character of the robot id that a ROS 2
// name cannot hold (anything but [A-Za-z0-9_]) written as '_'.
std::string ros_node_name(const std::string& robot_id);

// A DDS entity's GID as rmw forms it: the GUID's 12-byte prefix, its 4-byte entity id, then zeros
// up to the distro's GID size (24 bytes in Humble, 16 in Jazzy).
rmw_dds_common::msg::Gid to_gid(const eprosima::fastrtps::rtps::GUID_t& guid);

// The participant's one node: its namespace ("/" or "/<ns>"), its name, its ROS readers and writers.
rmw_dds_common::msg::ParticipantEntitiesInfo node_entities(
    const eprosima::fastrtps::rtps::GUID_t& participant, const std::string& ros_namespace,
    const std::string& node_name, const std::vector<eprosima::fastrtps::rtps::GUID_t>& readers,
    const std::vector<eprosima::fastrtps::rtps::GUID_t>& writers);

}  // namespace beaconloc::bridge
