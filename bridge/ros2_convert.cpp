#include "ros2_convert.hpp"

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/odometry_timeline.hpp"

#include <cmath>

namespace beaconloc::bridge {
namespace {

constexpr int kPlanarIndex[3] = {0, 1, 5};  // x, y, yaw in (x, y, z, roll, pitch, yaw)

// A conversion's refusal: the reason, for the caller to count, and nothing converted.
template <class T>
std::optional<T> refused(std::string* why_not, const std::string& reason) {
  if (why_not) *why_not = reason;
  return std::nullopt;
}

}  // namespace

builtin_interfaces::msg::Time to_ros_time(StampNs stamp_ns) {
  builtin_interfaces::msg::Time t;
  StampNs sec = stamp_ns / 1'000'000'000;
  StampNs nanosec = stamp_ns % 1'000'000'000;
  if (nanosec < 0) {  // floor division: nanosec always in [0, 1e9)
    nanosec += 1'000'000'000;
    --sec;
  }
  t.sec(static_cast<std::int32_t>(sec));
  t.nanosec(static_cast<std::uint32_t>(nanosec));
  return t;
}

std::optional<StampNs> from_ros_time(const builtin_interfaces::msg::Time& t) {
  // Zero is ROS's "no stamp": a measurement without a time cannot be fused.
  if (t.sec() < 0 || t.nanosec() >= 1'000'000'000u || (t.sec() == 0 && t.nanosec() == 0)) return std::nullopt;
  return static_cast<StampNs>(t.sec()) * 1'000'000'000 + static_cast<StampNs>(t.nanosec());
}

geometry_msgs::msg::Quaternion yaw_to_quaternion(double yaw_rad) {
  geometry_msgs::msg::Quaternion q;
  q.x(0.0);
  q.y(0.0);
  q.z(std::sin(yaw_rad / 2.0));
  q.w(std::cos(yaw_rad / 2.0));
  return q;
}

std::optional<double> planar_yaw(const geometry_msgs::msg::Quaternion& q) {
  const double x = q.x(), y = q.y(), z = q.z(), w = q.w();
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !std::isfinite(w)) return std::nullopt;
  const double norm = std::sqrt(x * x + y * y + z * z + w * w);
  if (std::abs(norm - 1.0) > 1e-3) return std::nullopt;
  // Roll and pitch from the standard ZYX decomposition; a planar robot's are zero.
  const double roll = std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
  const double pitch = std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0));
  if (std::abs(roll) > 1e-3 || std::abs(pitch) > 1e-3) return std::nullopt;
  return std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
}

void place_planar_covariance(const Cov3& c, double* out) {
  for (int i = 0; i < 36; ++i) out[i] = 0.0;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) out[kPlanarIndex[r] * 6 + kPlanarIndex[k]] = c(r, k);
  }
}

Cov3 planar_covariance(const double* in) {
  Cov3 c;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c(r, k) = in[kPlanarIndex[r] * 6 + kPlanarIndex[k]];
  }
  return c;
}

geometry_msgs::msg::PoseWithCovarianceStamped to_pose_with_covariance(const PoseEstimate& e,
                                                                      const std::string& map_frame) {
  geometry_msgs::msg::PoseWithCovarianceStamped m;
  m.header().stamp(to_ros_time(e.stamp_ns));
  m.header().frame_id(map_frame);
  m.pose().pose().position().x(e.pose_map_base.x());
  m.pose().pose().position().y(e.pose_map_base.y());
  m.pose().pose().position().z(0.0);
  m.pose().pose().orientation(yaw_to_quaternion(e.pose_map_base.z()));
  place_planar_covariance(e.covariance, m.pose().covariance().data());
  return m;
}

std::optional<InitialPose> from_initial_pose(const geometry_msgs::msg::PoseWithCovarianceStamped& m,
                                             std::string* why_not) {
  const auto stamp = from_ros_time(m.header().stamp());
  if (!stamp) return refused<InitialPose>(why_not, "bad_stamp");
  const auto yaw = planar_yaw(m.pose().pose().orientation());
  if (!yaw) return refused<InitialPose>(why_not, "not_a_planar_orientation");
  const double x = m.pose().pose().position().x(), y = m.pose().pose().position().y();
  if (!std::isfinite(x) || !std::isfinite(y)) return refused<InitialPose>(why_not, "non_finite_position");
  const Cov3 c = planar_covariance(m.pose().covariance().data());
  if (!c.allFinite() || !(c.diagonal().array() > 0.0).all())
    return refused<InitialPose>(why_not, "covariance_not_positive");
  return InitialPose{*stamp, Pose2(x, y, *yaw), c};
}

namespace {
constexpr int kTwistVx = 0;  // the twist covariance's rows: vx, vy, vz, wx, wy, wz
constexpr int kTwistWz = 5;
}  // namespace

Eigen::Matrix2d ros_twist_covariance(const nav_msgs::msg::Odometry& m) {
  const auto& c = m.twist().covariance();
  Eigen::Matrix2d out;
  out << c[kTwistVx * 6 + kTwistVx], c[kTwistVx * 6 + kTwistWz], c[kTwistWz * 6 + kTwistVx], c[kTwistWz * 6 + kTwistWz];
  return out;
}

std::optional<OdometrySample> from_ros_odometry(const nav_msgs::msg::Odometry& m, double wheel_base_m,
                                                std::string* why_not) {
  const auto stamp = from_ros_time(m.header().stamp());
  if (!stamp) return refused<OdometrySample>(why_not, "bad_stamp");
  const double v = m.twist().twist().linear().x(), omega = m.twist().twist().angular().z();
  if (!std::isfinite(v) || !std::isfinite(omega)) return refused<OdometrySample>(why_not, "non_finite_twist");
  // The (v, omega) covariance: finite, symmetric, variances >= 0 (a driver's unset one, all zeros,
  // is that too). Whether it is positive semi-definite is judged on the wheels' covariance it
  // becomes (the same for an invertible map), by the localizer's own check below.
  const Eigen::Matrix2d twist_covariance = ros_twist_covariance(m);
  if (!twist_covariance.allFinite() || twist_covariance(0, 1) != twist_covariance(1, 0) ||
      twist_covariance(0, 0) < 0.0 || twist_covariance(1, 1) < 0.0) {
    return refused<OdometrySample>(why_not, "bad_twist_covariance");
  }
  OdometrySample o;
  o.stamp_ns = *stamp;
  o.wheel_base_m = wheel_base_m;
  // v_R = v + omega B / 2, v_L = v - omega B / 2, and the covariance through the same map
  // (a driver's unset covariance, all zeros, stays zero: the estimator's floor applies).
  const Eigen::Vector2d wheels_mps = wheel_speeds_mps(v, omega, wheel_base_m);
  o.wheel_velocity_right_mps = wheels_mps(0);
  o.wheel_velocity_left_mps = wheels_mps(1);
  // J C J^T with J = wheel_speeds_per_twist = [[1, h], [1, -h]], h = B / 2, written out so that it
  // is exactly symmetric (a matrix product rounds its two off-diagonal entries differently, and
  // the localizer refuses an asymmetric covariance).
  const double h = wheel_base_m / 2.0;
  const double var_v = twist_covariance(0, 0), cov_v_omega = twist_covariance(0, 1), var_omega = twist_covariance(1, 1);
  const double right_left = var_v - h * h * var_omega;
  o.wheel_velocity_covariance << var_v + 2.0 * h * cov_v_omega + h * h * var_omega, right_left, right_left,
      var_v - 2.0 * h * cov_v_omega + h * h * var_omega;
  // What the localizer would refuse is refused here, by the same checks and reasons: a huge
  // finite twist is an infinite wheel speed on the bus.
  if (const InputResult checked = check_odometry_numbers(o); !checked.accepted) {
    return refused<OdometrySample>(why_not, to_string(*checked.rejection));
  }
  return o;
}

std::optional<LaserScanSample> from_ros_scan(const sensor_msgs::msg::LaserScan& m, std::string* why_not) {
  const auto stamp = from_ros_time(m.header().stamp());
  if (!stamp) return refused<LaserScanSample>(why_not, "bad_stamp");
  if (m.ranges().empty()) return refused<LaserScanSample>(why_not, "no_beams");
  if (!std::isfinite(m.angle_min()) || !std::isfinite(m.angle_increment()) || !std::isfinite(m.range_min()) ||
      !std::isfinite(m.range_max()) || !(m.range_max() > m.range_min()) || m.angle_increment() == 0.0f) {
    return refused<LaserScanSample>(why_not, "bad_scan_geometry");
  }
  // angle_max must be where the beams end (REP-117 scans carry both).
  const double last = m.angle_min() + static_cast<double>(m.ranges().size() - 1) * m.angle_increment();
  if (!std::isfinite(m.angle_max()) || std::abs(last - m.angle_max()) > std::abs(m.angle_increment())) {
    return refused<LaserScanSample>(why_not, "angles_do_not_match_the_beams");
  }
  LaserScanSample s;
  s.stamp_ns = *stamp;
  s.angle_min_rad = m.angle_min();
  s.angle_increment_rad = m.angle_increment();
  s.range_min_m = m.range_min();
  s.range_max_m = m.range_max();
  s.ranges_m = m.ranges();  // out-of-limit and non-finite beams are the estimator's to skip (REP-117)
  return s;
}

nav_msgs::msg::Odometry to_ros_odometry(const PoseEstimate& e, double v, double omega,
                                        const Eigen::Matrix2d& twist_covariance, const std::string& map_frame,
                                        const std::string& base_frame) {
  nav_msgs::msg::Odometry m;
  m.header().stamp(to_ros_time(e.stamp_ns));
  m.header().frame_id(map_frame);
  m.child_frame_id(base_frame);
  m.pose().pose().position().x(e.pose_map_base.x());
  m.pose().pose().position().y(e.pose_map_base.y());
  m.pose().pose().orientation(yaw_to_quaternion(e.pose_map_base.z()));
  place_planar_covariance(e.covariance, m.pose().covariance().data());
  m.twist().twist().linear().x(v);
  m.twist().twist().angular().z(omega);
  double* c = m.twist().covariance().data();
  for (int i = 0; i < 36; ++i) c[i] = 0.0;
  c[kTwistVx * 6 + kTwistVx] = twist_covariance(0, 0);
  c[kTwistVx * 6 + kTwistWz] = twist_covariance(0, 1);
  c[kTwistWz * 6 + kTwistVx] = twist_covariance(1, 0);
  c[kTwistWz * 6 + kTwistWz] = twist_covariance(1, 1);
  return m;
}

geometry_msgs::msg::TransformStamped to_transform(StampNs stamp_ns, const Pose2& p, const std::string& parent,
                                                  const std::string& child, double z_m) {
  geometry_msgs::msg::TransformStamped t;
  t.header().stamp(to_ros_time(stamp_ns));
  t.header().frame_id(parent);
  t.child_frame_id(child);
  t.transform().translation().x(p.x());
  t.transform().translation().y(p.y());
  t.transform().translation().z(z_m);
  t.transform().rotation(yaw_to_quaternion(p.z()));
  return t;
}

visualization_msgs::msg::MarkerArray beacon_markers(const BeaconMap& map, const std::string& map_frame,
                                                    StampNs stamp_ns) {
  constexpr std::int32_t kSphere = 2, kText = 9, kAdd = 0, kDeleteAll = 3;
  visualization_msgs::msg::MarkerArray out;
  // First clear what an earlier map drew: a beacon taken out of the map must leave the screen.
  visualization_msgs::msg::Marker clear;
  clear.header().stamp(to_ros_time(stamp_ns));
  clear.header().frame_id(map_frame);
  clear.action(kDeleteAll);
  clear.pose().orientation().w(1.0);
  out.markers().push_back(clear);
  for (const Beacon& b : map.beacons()) {
    for (const bool text : {false, true}) {
      visualization_msgs::msg::Marker m;
      m.header().stamp(to_ros_time(stamp_ns));
      m.header().frame_id(map_frame);
      m.ns(text ? "beacon_ids" : "beacons");
      m.id(static_cast<std::int32_t>(b.id));
      m.type(text ? kText : kSphere);
      m.action(kAdd);
      m.pose().position().x(b.position_map_m.x());
      m.pose().position().y(b.position_map_m.y());
      m.pose().position().z(b.position_map_m.z() + (text ? 0.25 : 0.0));
      m.pose().orientation().w(1.0);
      m.scale().x(text ? 0.0 : 0.15);
      m.scale().y(text ? 0.0 : 0.15);
      m.scale().z(0.15);
      m.color().r(text ? 1.0f : 0.1f);
      m.color().g(text ? 1.0f : 0.6f);
      m.color().b(text ? 1.0f : 1.0f);
      m.color().a(1.0f);
      if (text) m.text(std::to_string(b.id));
      out.markers().push_back(m);
    }
  }
  return out;
}

sensor_msgs::msg::Range to_ros_range(const RangeMeasurement& r, const std::string& receiver_frame,
                                     float field_of_view_rad, float min_range_m, float max_range_m) {
  sensor_msgs::msg::Range m;
  m.header().stamp(to_ros_time(r.stamp_ns));
  m.header().frame_id(receiver_frame);
  m.radiation_type(kRangeUltrasound);
  m.field_of_view(field_of_view_rad);
  m.min_range(min_range_m);
  m.max_range(max_range_m);
  m.range(static_cast<float>(r.range_m));
#if !defined(BEACONLOC_ROS2_HUMBLE)
  m.variance(static_cast<float>(r.variance_m2));
#endif
  return m;
}

}  // namespace beaconloc::bridge
