#pragma once
// The generated ROS 2 types of the distro chosen at build time (idl/CMakeLists.txt).
#include <ros2_common.h>
#include <ros2_commonPubSubTypes.h>
#include <ros2_graph.h>
#include <ros2_graphPubSubTypes.h>
#if defined(BEACONLOC_ROS2_HUMBLE)
#include <ros2_humble.h>
#include <ros2_humblePubSubTypes.h>
#else
#include <ros2_jazzy.h>
#include <ros2_jazzyPubSubTypes.h>
#endif

namespace beaconloc::bridge {
#if defined(BEACONLOC_ROS2_HUMBLE)
inline constexpr const char* kRos2Distro = "humble";
#else
inline constexpr const char* kRos2Distro = "jazzy";
#endif
inline constexpr std::uint8_t kRangeUltrasound = 0;  // sensor_msgs/Range ULTRASOUND
}  // namespace beaconloc::bridge
