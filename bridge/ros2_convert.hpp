#pragma once
// Conversions between the project's core types and the ROS 2 messages of idl/ros2 (REP-103
// units, REP-105 frames). Pure functions: the bridge participant wires them to topics.
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/measurements.hpp"
#include "ros2_types.hpp"

namespace beaconloc::bridge {

builtin_interfaces::msg::Time to_ros_time(StampNs stamp_ns);
// nullopt for a time ROS would not send (negative seconds, nanosec >= 1e9).
std::optional<StampNs> from_ros_time(const builtin_interfaces::msg::Time& t);

geometry_msgs::msg::Quaternion yaw_to_quaternion(double yaw_rad);
// The yaw of a quaternion that is a rotation about z (roll and pitch within 1e-3 rad); nullopt
// for a non-finite, non-unit or tilted one: a planar robot cannot use it.
std::optional<double> planar_yaw(const geometry_msgs::msg::Quaternion& q);

// The 3 x 3 (x, y, yaw) covariance in the 6 x 6 (x, y, z, roll, pitch, yaw), row-major; the
// unestimated z, roll and pitch left 0 as Nav2's amcl_pose does.
void place_planar_covariance(const Cov3& c, double* covariance36);
Cov3 planar_covariance(const double* covariance36);

geometry_msgs::msg::PoseWithCovarianceStamped to_pose_with_covariance(const PoseEstimate& e,
                                                                      const std::string& map_frame);

// A pose from rviz2's "2D Pose Estimate" or Nav2 (initialpose): nullopt with a reason when unusable.
struct InitialPose {
  StampNs stamp_ns;
  Pose2 pose_map_base;
  Cov3 covariance;
};
std::optional<InitialPose> from_initial_pose(const geometry_msgs::msg::PoseWithCovarianceStamped& m,
                                             std::string* why_not);

// Odometry of a ROS 2 robot driver (twist in the base frame: linear.x, angular.z) as the wheel
// velocities of a differential drive of wheel_base_m, with their covariance from the twist's.
// The (linear.x, angular.z) block of a nav_msgs/Odometry's twist covariance (row-major 6x6 over
// vx, vy, vz, wx, wy, wz), as given: from_ros_odometry checks it.
Eigen::Matrix2d ros_twist_covariance(const nav_msgs::msg::Odometry& m);
std::optional<OdometrySample> from_ros_odometry(const nav_msgs::msg::Odometry& m, double wheel_base_m,
                                                std::string* why_not);

std::optional<LaserScanSample> from_ros_scan(const sensor_msgs::msg::LaserScan& m, std::string* why_not);

// The pose estimate with the robot's twist (from its wheel odometry) as nav_msgs/Odometry: the
// twist's covariance is twist_covariance over (linear.x, angular.z); the other components of a
// planar robot's twist are 0 with 0 variance, as the pose's z, roll and pitch.
nav_msgs::msg::Odometry to_ros_odometry(const PoseEstimate& e, double v_mps, double omega_radps,
                                        const Eigen::Matrix2d& twist_covariance, const std::string& map_frame,
                                        const std::string& base_frame);

geometry_msgs::msg::TransformStamped to_transform(StampNs stamp_ns, const Pose2& parent_child,
                                                  const std::string& parent, const std::string& child,
                                                  double z_m = 0.0);

// One sphere per beacon with a map position (and its id as text above it), in the map frame; a
// locally referenced beacon (seed 003, not calibrated) has none to draw.
visualization_msgs::msg::MarkerArray beacon_markers(const BeaconMap& map, const std::string& map_frame,
                                                    StampNs stamp_ns);

sensor_msgs::msg::Range to_ros_range(const RangeMeasurement& r, const std::string& receiver_frame,
                                     float field_of_view_rad, float min_range_m, float max_range_m);

}  // namespace beaconloc::bridge
