// The ROS 2 bridge's conversions and frame maths (no DDS traffic): REP-103/105 conventions, the
// 3 x 3 covariance in the 6 x 6, a driver's twist as wheel speeds, map -> odom, and the type
// names on the wire exactly as ROS 2 names them.
#include <gtest/gtest.h>

#include <cmath>

#include "odom_frame.hpp"
#include "pending_transforms.hpp"
#include "ros2_convert.hpp"

namespace beaconloc::bridge {
namespace {

TEST(Ros2Bridge, TypeNamesOnTheWireAreTheRos2Ones) {
  EXPECT_EQ(geometry_msgs::msg::PoseWithCovarianceStampedPubSubType().getName(),
            std::string("geometry_msgs::msg::dds_::PoseWithCovarianceStamped_"));
  EXPECT_EQ(nav_msgs::msg::OdometryPubSubType().getName(), std::string("nav_msgs::msg::dds_::Odometry_"));
  EXPECT_EQ(tf2_msgs::msg::TFMessagePubSubType().getName(), std::string("tf2_msgs::msg::dds_::TFMessage_"));
  EXPECT_EQ(visualization_msgs::msg::MarkerArrayPubSubType().getName(),
            std::string("visualization_msgs::msg::dds_::MarkerArray_"));
  EXPECT_EQ(sensor_msgs::msg::LaserScanPubSubType().getName(),
            std::string("sensor_msgs::msg::dds_::LaserScan_"));
  EXPECT_EQ(sensor_msgs::msg::RangePubSubType().getName(), std::string("sensor_msgs::msg::dds_::Range_"));
  // ROS topics are unkeyed: a keyed type would not match a ROS 2 endpoint.
  EXPECT_FALSE(nav_msgs::msg::OdometryPubSubType().m_isGetKeyDefined);
  EXPECT_FALSE(geometry_msgs::msg::PoseWithCovarianceStampedPubSubType().m_isGetKeyDefined);
}

TEST(Ros2Bridge, TimeAndOrientationFollowRep103) {
  const auto t = to_ros_time(1'234'567'890'123);
  EXPECT_EQ(t.sec(), 1234);
  EXPECT_EQ(t.nanosec(), 567'890'123u);
  EXPECT_EQ(from_ros_time(t), 1'234'567'890'123);
  builtin_interfaces::msg::Time bad;
  bad.nanosec(1'000'000'000u);
  EXPECT_FALSE(from_ros_time(bad));
  for (double yaw : {-3.0, -1.0, 0.0, 0.5, 2.9}) EXPECT_NEAR(*planar_yaw(yaw_to_quaternion(yaw)), yaw, 1e-12);
  geometry_msgs::msg::Quaternion tilted;  // 90 degrees about x
  tilted.x(std::sqrt(0.5));
  tilted.w(std::sqrt(0.5));
  EXPECT_FALSE(planar_yaw(tilted));
  geometry_msgs::msg::Quaternion zero;  // not a rotation
  EXPECT_FALSE(planar_yaw(zero));
}

TEST(Ros2Bridge, PoseCovarianceGoesToXYYawOfTheSixBySix) {
  PoseEstimate e;
  e.stamp_ns = 5'000'000'000;
  e.pose_map_base = Pose2(1.5, -2.0, 0.7);
  e.covariance << 0.04, 0.01, 0.002, 0.01, 0.09, 0.003, 0.002, 0.003, 0.0025;
  const auto m = to_pose_with_covariance(e, "map");
  EXPECT_EQ(m.header().frame_id(), "map");
  EXPECT_EQ(m.header().stamp().sec(), 5);
  EXPECT_EQ(m.pose().pose().position().x(), 1.5);
  EXPECT_EQ(m.pose().pose().position().y(), -2.0);
  EXPECT_NEAR(*planar_yaw(m.pose().pose().orientation()), 0.7, 1e-12);
  const auto& c = m.pose().covariance();
  EXPECT_EQ(c[0 * 6 + 0], 0.04);
  EXPECT_EQ(c[0 * 6 + 1], 0.01);
  EXPECT_EQ(c[0 * 6 + 5], 0.002);
  EXPECT_EQ(c[1 * 6 + 1], 0.09);
  EXPECT_EQ(c[5 * 6 + 5], 0.0025);
  EXPECT_EQ(c[2 * 6 + 2], 0.0);  // z, roll, pitch unestimated, left 0 as amcl_pose does
  EXPECT_EQ(planar_covariance(c.data()), e.covariance);
  // An initialpose from rviz2 comes back as the same pose and covariance.
  std::string why;
  const auto init = from_initial_pose(m, &why);
  ASSERT_TRUE(init) << why;
  EXPECT_TRUE(init->pose_map_base.isApprox(e.pose_map_base, 1e-12));
  EXPECT_EQ(init->covariance, e.covariance);
}

TEST(Ros2Bridge, DriverOdometryBecomesWheelSpeedsAndBadOnesAreRefused) {
  nav_msgs::msg::Odometry m;
  m.header().stamp(to_ros_time(2'000'000'000));
  m.twist().twist().linear().x(0.5);
  m.twist().twist().angular().z(0.2);
  m.twist().covariance()[0] = 0.01;
  m.twist().covariance()[35] = 0.04;
  std::string why;
  const auto o = from_ros_odometry(m, 0.4, &why);
  ASSERT_TRUE(o) << why;
  EXPECT_EQ(o->stamp_ns, 2'000'000'000);
  EXPECT_NEAR(o->wheel_velocity_right_mps, 0.5 + 0.2 * 0.2, 1e-12);
  EXPECT_NEAR(o->wheel_velocity_left_mps, 0.5 - 0.2 * 0.2, 1e-12);
  // Back through the same map: v and omega's variances.
  EXPECT_NEAR((o->wheel_velocity_covariance(0, 0) + o->wheel_velocity_covariance(1, 1) +
               2 * o->wheel_velocity_covariance(0, 1)) /
                  4.0,
              0.01, 1e-12);
  // A cross term of v and omega goes to the wheels, exactly symmetric (for every valid one: the
  // localizer refuses an asymmetric covariance).
  for (const double cross : {0.005, -0.013, 1e-3 / 3.0, 0.019}) {
    m.twist().covariance()[5] = m.twist().covariance()[30] = cross;
    const auto with_cross = from_ros_odometry(m, 0.4, &why);
    ASSERT_TRUE(with_cross) << cross << " " << why;
    EXPECT_EQ(with_cross->wheel_velocity_covariance(0, 1), with_cross->wheel_velocity_covariance(1, 0)) << cross;
  }
  // A covariance that is no covariance (asymmetric, negative, not positive semi-definite) is
  // refused, not repaired.
  m.twist().covariance()[5] = 0.001;
  m.twist().covariance()[30] = 0.002;
  EXPECT_FALSE(from_ros_odometry(m, 0.4, &why));
  EXPECT_EQ(why, "bad_twist_covariance");
  m.twist().covariance()[5] = m.twist().covariance()[30] = 0.05;  // 0.05^2 > 0.01 * 0.04
  EXPECT_FALSE(from_ros_odometry(m, 0.4, &why));
  EXPECT_EQ(why, "invalid_odometry_covariance");
  m.twist().covariance()[5] = m.twist().covariance()[30] = 0.0;
  m.twist().covariance()[35] = -0.04;
  EXPECT_FALSE(from_ros_odometry(m, 0.4, &why));
  EXPECT_EQ(why, "bad_twist_covariance");
  m.twist().covariance()[35] = 0.04;
  m.twist().twist().linear().x(std::nan(""));
  EXPECT_FALSE(from_ros_odometry(m, 0.4, &why));
  EXPECT_EQ(why, "non_finite_twist");
  // Finite but absurd: refused as the localizer refuses it, not sent on as inf wheel speeds.
  for (double v : {1e300, 1000.0, 10.5}) {
    m.twist().twist().linear().x(v);
    EXPECT_FALSE(from_ros_odometry(m, 0.4, &why)) << v;
    EXPECT_EQ(why, "implausible_wheel_speed") << v;
  }
  m.twist().twist().linear().x(0.5);
  m.twist().twist().angular().z(1e300);
  EXPECT_FALSE(from_ros_odometry(m, 0.4, &why));
  EXPECT_EQ(why, "implausible_wheel_speed");
  m.twist().twist().angular().z(0.2);
  m.twist().covariance()[0] = 1e300;
  EXPECT_FALSE(from_ros_odometry(m, 0.4, &why));
  EXPECT_EQ(why, "invalid_odometry_covariance");
  sensor_msgs::msg::LaserScan scan;
  EXPECT_FALSE(from_ros_scan(scan, &why));
  EXPECT_EQ(why, "bad_stamp");  // zero: ROS's "no stamp"
  scan.header().stamp(to_ros_time(3'000'000'000));
  EXPECT_FALSE(from_ros_scan(scan, &why));
  EXPECT_EQ(why, "no_beams");
  scan.ranges({1.0f, 2.0f, 3.0f});
  scan.angle_min(-0.5f);
  scan.angle_increment(0.5f);
  scan.angle_max(0.5f);
  scan.range_max(10.0f);
  ASSERT_TRUE(from_ros_scan(scan, &why)) << why;
  scan.angle_max(2.0f);  // says five beams, carries three
  EXPECT_FALSE(from_ros_scan(scan, &why));
  EXPECT_EQ(why, "angles_do_not_match_the_beams");
}

TEST(Ros2Bridge, MapToOdomComposesToTheEstimate) {
  OdomFrame odom;
  OdometrySample o;
  o.wheel_base_m = 0.4;
  o.stamp_ns = 0;
  ASSERT_TRUE(odom.add_wheel_odometry(o).accepted);  // anchor: odom -> base = identity at t = 0
  o.wheel_velocity_right_mps = 0.6;
  o.wheel_velocity_left_mps = 0.4;
  for (int k = 1; k <= 100; ++k) {
    o.stamp_ns = k * 10'000'000;
    ASSERT_TRUE(odom.add_wheel_odometry(o).accepted);
  }
  EXPECT_EQ(odom.add_wheel_odometry(o).rejection, Rejection::kDuplicateOdometry);  // same stamp again
  o.stamp_ns -= 5'000'000;
  EXPECT_EQ(odom.add_wheel_odometry(o).rejection, Rejection::kOutOfOrderOdometry);
  o.stamp_ns += 5'000'000;
  // The bus's odometry is checked as the estimators check it: an absurd speed never moves the
  // frame (it put odom -> base_link and the published twist at infinity).
  for (double v : {1e300, 1000.0}) {
    o.stamp_ns += 10'000'000;
    o.wheel_velocity_right_mps = v;
    EXPECT_EQ(odom.add_wheel_odometry(o).rejection, Rejection::kImplausibleWheelSpeed) << v;
  }
  EXPECT_EQ(*odom.latest_stamp_ns(), 1'000'000'000);
  EXPECT_NEAR(odom.v_mps(), 0.5, 1e-12);
  const Pose2 map_base(3.0, 1.0, 0.4);
  const auto map_odom = odom.pose_map_odom(1'000'000'000, map_base);
  ASSERT_TRUE(map_odom);
  // map -> odom composed with odom -> base gives the estimate back.
  const Pose2 back = compose(*map_odom, *odom.pose_odom_base(1'000'000'000));
  EXPECT_TRUE(back.isApprox(map_base, 1e-12)) << back.transpose();
  EXPECT_NEAR(odom.v_mps(), 0.5, 1e-12);
  EXPECT_NEAR(odom.omega_radps(), 0.5, 1e-12);
  // Between two samples: interpolated (half way between the 0.99 s and 1.00 s poses).
  const Pose2 a = *odom.pose_odom_base(990'000'000), b = *odom.pose_odom_base(1'000'000'000);
  EXPECT_TRUE(odom.pose_odom_base(995'000'000)->isApprox(0.5 * (a + b), 1e-12));
  // Outside the history: none.
  EXPECT_FALSE(odom.pose_odom_base(2'000'000'000));
}

// odometry/beacons states what the wheels support: their reported covariance carried to (v, omega)
// (v = (v_R + v_L) / 2, omega = (v_R - v_L) / B), at (vx, wz) of the 6x6; before any odometry, a
// twist not known (a large variance), never a certain standstill; a driver's own covariance as given.
TEST(Ros2Bridge, TheOdometrysTwistCovarianceIsTheWheelsCarriedToVAndOmega) {
  OdomFrame odom;
  EXPECT_EQ(odom.twist_covariance(), OdomFrame::kUnknownTwistVariance * Eigen::Matrix2d::Identity());
  OdometrySample o;
  o.wheel_base_m = 0.5;
  o.wheel_velocity_right_mps = 0.3;
  o.wheel_velocity_left_mps = 0.1;
  o.wheel_velocity_covariance << 4e-4, 1e-4, 1e-4, 9e-4;
  ASSERT_TRUE(odom.add_wheel_odometry(o).accepted);
  // By hand: var_v = (4 + 2 + 9) e-4 / 4; cov = (4 - 9) e-4 / (2 B); var_w = (4 - 2 + 9) e-4 / B^2.
  const Eigen::Matrix2d& c = odom.twist_covariance();
  EXPECT_NEAR(c(0, 0), 15e-4 / 4.0, 1e-15);
  EXPECT_NEAR(c(0, 1), -5e-4 / 1.0, 1e-15);
  EXPECT_EQ(c(1, 0), c(0, 1));  // exactly: a covariance on the wire is symmetric
  EXPECT_NEAR(c(1, 1), 11e-4 / 0.25, 1e-15);

  PoseEstimate e;
  e.stamp_ns = 1;
  const nav_msgs::msg::Odometry m = to_ros_odometry(e, odom.v_mps(), odom.omega_radps(), c, "map", "base_link");
  EXPECT_EQ(m.twist().twist().linear().x(), 0.2);
  EXPECT_EQ(ros_twist_covariance(m), c);
  for (int i = 0; i < 36; ++i) {
    if (i != 0 && i != 5 && i != 30 && i != 35) {
      EXPECT_EQ(m.twist().covariance()[i], 0.0) << i;
    }
  }
  // A driver feeding the frame (--odom-in): its own covariance.
  Eigen::Matrix2d driver;
  driver << 0.01, 0.0, 0.0, 0.04;
  ASSERT_TRUE(odom.add_odom_pose(2'000'000'000, Pose2(1.0, 0.0, 0.0), 0.5, 0.2, driver));
  EXPECT_EQ(odom.twist_covariance(), driver);
  EXPECT_FALSE(odom.add_odom_pose(3'000'000'000, Pose2(1.0, 0.0, 0.0), 0.5, 0.2,
                                  Eigen::Matrix2d::Constant(std::nan(""))));
}

// A clock that steps forward (a gateway stamping data time replaced by one stamping wall-clock
// time) is a gap: not integrated (1.7e9 s at 1 m/s put the frame beyond any site, and every later
// sample was refused, freezing map -> odom), but taken, and the frame goes on from where it was.
TEST(Ros2Bridge, TheOdomFrameGoesOnAcrossAClockStepForward) {
  OdomFrame odom;
  OdometrySample o;
  o.wheel_base_m = 0.4;
  o.wheel_velocity_right_mps = 1.0;
  o.wheel_velocity_left_mps = 1.0;
  for (int k = 0; k <= 10; ++k) {
    o.stamp_ns = k * 10'000'000;
    ASSERT_TRUE(odom.add_wheel_odometry(o).accepted);
  }
  const Pose2 before = *odom.pose_odom_base(100'000'000);
  EXPECT_NEAR(before.x(), 0.1, 1e-9);
  const StampNs jumped_ns = 1'700'000'000'000'000'000;
  o.stamp_ns = jumped_ns;
  EXPECT_EQ(odom.add_wheel_odometry(o).rejection, Rejection::kOdometryGap);
  ASSERT_TRUE(odom.pose_odom_base(jumped_ns));
  EXPECT_TRUE(odom.pose_odom_base(jumped_ns)->isApprox(before, 1e-12));  // not integrated
  o.stamp_ns = jumped_ns + 10'000'000;
  ASSERT_TRUE(odom.add_wheel_odometry(o).accepted);
  EXPECT_NEAR(odom.pose_odom_base(o.stamp_ns)->x(), 0.11, 1e-9);  // and on from there
}

TEST(Ros2Bridge, BeaconMarkersAndRanges) {
  const BeaconMap map({{1, {0.0, 0.0, 2.0}}, {7, {3.0, 1.0, 2.5}}});
  const auto markers = beacon_markers(map, "map", 0);
  ASSERT_EQ(markers.markers().size(), 5u);      // clear all, then a sphere and an id text per beacon
  EXPECT_EQ(markers.markers()[0].action(), 3);  // DELETEALL: a removed beacon leaves the screen
  EXPECT_EQ(markers.markers()[3].id(), 7);
  EXPECT_EQ(markers.markers()[3].pose().position().z(), 2.5);
  EXPECT_EQ(markers.markers()[4].text(), "7");
  RangeMeasurement r;
  r.stamp_ns = 1;
  r.range_m = 2.25;
  r.variance_m2 = 1e-4;
  const auto range = to_ros_range(r, "receiver_0", 2.0f, 0.0f, 15.0f);
  EXPECT_EQ(range.radiation_type(), kRangeUltrasound);
  EXPECT_EQ(range.range(), 2.25f);
  EXPECT_EQ(range.header().frame_id(), "receiver_0");
}

// A correction (a pose at the previous pose's stamp) replaces the pose still waiting for its
// odometry; once that stamp's transform is out, a correction is dropped (tf2 would warn of a
// repeat); poses wait until the odometry reaches their stamp; a full queue gives the oldest up.
TEST(Ros2Bridge, PendingTransformsTakeCorrectionsOnceAndWaitForOdometry) {
  auto pose = [](StampNs stamp_ns, double x_m) {
    PoseEstimate e;
    e.stamp_ns = stamp_ns;
    e.pose_map_base = Pose2(x_m, 0.0, 0.0);
    return e;
  };
  PendingTransforms pending(3);
  using Added = PendingTransforms::Added;
  EXPECT_EQ(pending.add(pose(10, 1.0)), Added::kQueued);
  EXPECT_EQ(pending.add(pose(10, 1.5)), Added::kReplacedWaiting);
  EXPECT_EQ(pending.add(pose(20, 2.0)), Added::kQueued);
  EXPECT_TRUE(pending.take_reached(9).empty());
  const auto reached = pending.take_reached(15);
  ASSERT_EQ(reached.size(), 1u);
  EXPECT_EQ(reached[0].pose_map_base.x(), 1.5);
  pending.published(10);
  EXPECT_EQ(pending.add(pose(10, 1.6)), Added::kAlreadyPublished);
  EXPECT_EQ(pending.size(), 1u);
  EXPECT_EQ(pending.add(pose(30, 3.0)), Added::kQueued);
  EXPECT_EQ(pending.add(pose(40, 4.0)), Added::kQueued);
  EXPECT_EQ(pending.add(pose(50, 5.0)), Added::kQueuedDroppedOldest);
  const auto rest = pending.take_reached(100);
  ASSERT_EQ(rest.size(), 3u);
  EXPECT_EQ(rest.front().stamp_ns, 30);
}

}  // namespace
}  // namespace beaconloc::bridge
