// The simulated source: deterministic by seed, TOF from the flight geometry including the
// robot's motion during the flight, odometry consistent with the truth and noisy as modelled.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/speed_of_sound.hpp"
#include "sim/sim_source.hpp"

namespace beaconloc::sim {
namespace {

std::vector<SourceEvent> run(const Scenario& s, std::uint64_t seed, double seconds) {
  SimSource source(s, seed);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(seconds), events);
  return events;
}

bool same(const SourceEvent& a, const SourceEvent& b) {
  return a.kind == b.kind && a.stamp_ns == b.stamp_ns && a.tof.tof_s == b.tof.tof_s &&
         a.tof.beacon_id == b.tof.beacon_id &&
         a.odometry.wheel_velocity_right_mps == b.odometry.wheel_velocity_right_mps &&
         a.odometry.wheel_velocity_left_mps == b.odometry.wheel_velocity_left_mps;
}

TEST(SimSource, SameSeedSameStreamOtherSeedOtherStream) {
  const auto a = run(default_scenario(), 7, 5.0), b = run(default_scenario(), 7, 5.0),
             c = run(default_scenario(), 8, 5.0);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(same(a[i], b[i])) << i;
  std::size_t differing = 0;
  for (std::size_t i = 0; i < std::min(a.size(), c.size()); ++i) differing += !same(a[i], c[i]);
  EXPECT_GT(differing, a.size() / 2);
}

TEST(SimSource, EventsComeInStampOrderAtTheScenarioRates) {
  const auto events = run(default_scenario(), 1, 10.0);
  std::size_t odometry = 0, tofs = 0;
  for (std::size_t i = 1; i < events.size(); ++i) ASSERT_LE(events[i - 1].stamp_ns, events[i].stamp_ns);
  for (const auto& e : events) (e.kind == SourceEvent::Kind::kOdometry ? odometry : tofs)++;
  EXPECT_EQ(odometry, 1000u);  // 100 Hz
  EXPECT_EQ(tofs, 50u * 3u);   // 5 Hz slots x 3 receivers, every beacon in range
}

TEST(SimSource, StaticRobotTofIsTheDistanceOverTheSpeedOfSound) {
  Scenario s = default_scenario();
  s.trajectory = Trajectory({1.0, 0.4, 0.3}, {{100.0, 0.0, 0.0}}, false);
  s.range_sigma_m = 0.0;
  const double c = speed_of_sound_mps(s.temperature_c);
  for (const auto& e : run(s, 1, 2.0)) {
    if (e.kind != SourceEvent::Kind::kTof) continue;
    const Eigen::Vector2d rx =
        transform_point(s.trajectory.pose_at(0.0), s.receivers.receivers_base_m[e.tof.receiver_id]);
    Eigen::Vector3d beacon = Eigen::Vector3d::Zero();
    for (const auto& b : s.beacons)
      if (b.id == e.tof.beacon_id) beacon = b.position_map_m;
    const double d = Eigen::Vector3d(rx.x() - beacon.x(), rx.y() - beacon.y(), -beacon.z()).norm();
    EXPECT_NEAR(e.tof.tof_s, d / c, 1e-12);
  }
}

// Seed 003 Sec. 2: a group covers a circle around its centre; a receiver hears every beacon of
// the group inside it and none outside, whatever each beacon's own limits allow. Group 0 (a site
// of one group) has no circle.
TEST(SimSource, AGroupIsHeardWithinItsCoverageCircleAndNotBeyond) {
  Scenario s = default_scenario();  // six beacons at 2.011 m: (0, 1.5, 3) x (-0.3, 1.5)
  s.max_range_m = 20.0;
  s.range_sigma_m = 0.0;
  for (Beacon& b : s.beacons) b.group = b.position_map_m.y() < 0.0 ? 1 : 2;
  s.group_coverage_radius_m = 1.0;
  const auto centres = s.group_centres_map_m();
  ASSERT_EQ(centres.size(), 2u);
  EXPECT_TRUE(centres.at(1).isApprox(Eigen::Vector2d(1.5, -0.3)));
  EXPECT_TRUE(centres.at(2).isApprox(Eigen::Vector2d(1.5, 1.5)));
  s.receivers = ReceiverArray::on_circle(0.0, 1);
  const auto heard_at = [&](double x_m, double y_m) {
    s.trajectory = Trajectory({x_m, y_m, 0.0}, {{100.0, 0.0, 0.0}}, false);
    std::set<std::uint32_t> ids;
    for (const auto& e : run(s, 1, 3.0))
      if (e.kind == SourceEvent::Kind::kTof) ids.insert(e.tof.beacon_id);
    return ids;
  };
  const std::set<std::uint32_t> group_1 = {1, 2, 3}, none;
  EXPECT_EQ(heard_at(1.5 + 0.99, -0.3), group_1);  // just inside group 1's circle: all three of it
  EXPECT_EQ(heard_at(1.5 + 1.01, -0.3), none);     // just outside: none of it; group 2 is 2 m away
  // A group 0 beacon is heard by its own limits alone: beacon 4, (0, 1.5), 3 m away.
  s.beacons[3].group = 0;
  EXPECT_EQ(heard_at(1.5 + 1.01, -0.3), std::set<std::uint32_t>{4});
  // Where the robot is nearest a locally referenced group's centre.
  s.local_group_frames_map[2] = Pose2(1.5, 1.5, 0.0);
  EXPECT_TRUE(s.nearest_group_is_local(1.5, 1.0));
  EXPECT_FALSE(s.nearest_group_is_local(1.5, 0.5));
}

TEST(SimSource, MovingRobotHearsThePulseWhereItIsAtArrival) {
  // Kleeman (seed 002) eq. 20: the receiver keeps moving during the flight. At 1.02 m/s toward
  // a beacon the flight is shorter than from the firing pose by about v * tof / c.
  Scenario s = default_scenario();
  s.trajectory = Trajectory({0.0, 0.0, 0.0}, {{100.0, 1.02, 0.0}}, false);
  s.beacons = {{1, {6.0, 0.0, 2.0}, 0}};
  s.firing_order = {1};
  s.max_range_m = 10.0;
  s.range_sigma_m = 0.0;
  const double c = speed_of_sound_mps(s.temperature_c);
  int checked = 0;
  for (const auto& e : run(s, 1, 2.0)) {
    if (e.kind != SourceEvent::Kind::kTof) continue;
    const double fire_s = ns_to_s(e.tof.fire_stamp_ns), arrival_s = fire_s + e.tof.tof_s;
    const Eigen::Vector3d beacon = s.beacons[0].position_map_m;
    auto distance_at = [&](double t) {
      const Eigen::Vector2d rx =
          transform_point(s.trajectory.pose_at(t), s.receivers.receivers_base_m[e.tof.receiver_id]);
      return Eigen::Vector3d(rx.x() - beacon.x(), rx.y() - beacon.y(), -beacon.z()).norm();
    };
    EXPECT_NEAR(e.tof.tof_s * c, distance_at(arrival_s), 1e-9);  // self-consistent flight
    const double static_tof = distance_at(fire_s) / c;
    const double closing_mps = (distance_at(fire_s) - distance_at(fire_s + 1e-3)) / 1e-3;
    EXPECT_NEAR(static_tof - e.tof.tof_s, static_tof * closing_mps / (c + closing_mps), 1e-7);
    EXPECT_GT(static_tof - e.tof.tof_s, 1e-5);  // > 3 mm: not negligible
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

TEST(SimSource, NoiseFreeOdometryIntegratesToTheTruth) {
  Scenario s = default_scenario();
  s.odometry_k_v_m = 0.0;
  Pose2 pose = s.trajectory.pose_at(0.0);
  StampNs last = 0;
  Pose2 truth = pose;
  for (const auto& e : run(s, 1, 30.0)) {
    if (e.kind != SourceEvent::Kind::kOdometry) continue;
    pose = predict_diff_drive(pose, e.odometry.wheel_velocity_right_mps, e.odometry.wheel_velocity_left_mps,
                              e.odometry.wheel_base_m, ns_to_s(e.stamp_ns - last))
               .pose;
    last = e.stamp_ns;
    truth = e.truth_map_base;
  }
  EXPECT_LT((pose.head<2>() - truth.head<2>()).norm(), 1e-3);
  EXPECT_LT(std::abs(wrap_angle_rad(pose.z() - truth.z())), 1e-3);
}

TEST(SimSource, OdometryNoiseFollowsTheSpeedProportionalModel) {
  // Seed 000: sigma_v^2 = k_v |v| / dT per wheel; straight at 0.34 m/s -> 0.0136 m^2/s^2.
  Scenario s = default_scenario();
  s.trajectory = Trajectory({0.0, 0.0, 0.0}, {{1000.0, 0.34, 0.0}}, false);
  double sum = 0.0, sum_sq = 0.0;
  int n = 0;
  for (const auto& e : run(s, 3, 200.0)) {
    if (e.kind != SourceEvent::Kind::kOdometry) continue;
    const double err = e.odometry.wheel_velocity_right_mps - 0.34;
    sum += err;
    sum_sq += err * err;
    ++n;
  }
  const double expected = 4e-4 * 0.34 / 0.01;
  EXPECT_NEAR(sum / n, 0.0, 5.0 * std::sqrt(expected / n));
  EXPECT_NEAR(sum_sq / n, expected, 0.05 * expected);
}

// Beacons without a radio message (seed 002): pulse arrivals only, at the arrival the time of
// flight gives, the marked beacon's as double bursts and every other as single.
TEST(SimSource, WithoutRadioSyncTheReceiverHearsPulseArrivalsMarkedByTheDoubleBurst) {
  Scenario s = default_scenario();
  const auto tofs = run(s, 3, 4.0);
  s.identified = false;
  s.radio_sync = false;
  s.marked_beacon_id = s.firing_order.front();
  SimSource source(s, 3);
  EXPECT_EQ(source.beacon_input(), BeaconInput::kPulseArrivals);
  const auto pulses = run(s, 3, 4.0);
  ASSERT_EQ(tofs.size(), pulses.size());
  std::size_t doubles = 0;
  for (std::size_t i = 0; i < tofs.size(); ++i) {
    EXPECT_NE(pulses[i].kind, SourceEvent::Kind::kTof);
    if (tofs[i].kind != SourceEvent::Kind::kTof) continue;
    ASSERT_EQ(pulses[i].kind, SourceEvent::Kind::kPulse);
    EXPECT_EQ(pulses[i].pulse.stamp_ns, tofs[i].tof.fire_stamp_ns + s_to_ns(tofs[i].tof.tof_s));
    EXPECT_EQ(pulses[i].pulse.receiver_id, tofs[i].tof.receiver_id);
    const bool marked = pulses[i].true_beacon_id == *s.marked_beacon_id;
    EXPECT_EQ(pulses[i].pulse.mark, marked ? PulseMark::kDouble : PulseMark::kSingle);
    doubles += marked;
  }
  EXPECT_GT(doubles, 0u);
}

}  // namespace
}  // namespace beaconloc::sim
