// Each physical effect of the simulator changes the raw measurements as it should: coverage
// (range and beam), the speed of sound from the temperature, echoes, systematic odometry errors,
// anonymous pulses, laser rays on the map.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "beaconloc/core/speed_of_sound.hpp"
#include "sim/laser_world.hpp"
#include "sim/sim_source.hpp"

namespace beaconloc::sim {
namespace {

// One beacon above a robot standing still at the origin, noise-free.
Scenario still_world() {
  Scenario s;
  s.beacons = {{1, {0.0, 0.0, 2.0}, 0}, {2, {3.0, 0.0, 2.0}, 0}};
  s.firing_order = {1, 2};
  s.receivers.receivers_base_m = {{0.0, 0.0}};
  s.range_sigma_m = 0.0;
  s.max_range_m = 10.0;
  s.trajectory = Trajectory({0.0, 0.0, 0.0}, {{1000.0, 0.0, 0.0}}, false);
  return s;
}

std::vector<SourceEvent> tofs(const Scenario& s, double seconds, std::uint64_t seed = 1) {
  SimSource source(s, seed);
  std::vector<SourceEvent> all, out;
  source.advance(s_to_ns(seconds), all);
  for (const auto& e : all) {
    if (e.kind == SourceEvent::Kind::kTof) out.push_back(e);
  }
  return out;
}

std::map<std::uint32_t, int> heard(const std::vector<SourceEvent>& events) {
  std::map<std::uint32_t, int> n;
  for (const auto& e : events) ++n[e.true_beacon_id];
  return n;
}

TEST(SimPhysics, ReceiversHearOnlyBeaconsInRange) {
  Scenario s = still_world();
  EXPECT_EQ(heard(tofs(s, 2.0)).size(), 2u);
  s.max_range_m = 3.0;  // beacon 2 is sqrt(9 + 4) = 3.61 m away
  auto n = heard(tofs(s, 2.0));
  EXPECT_EQ(n.count(2), 0u);
  EXPECT_EQ(n[1], 5);
  s.max_range_m = 10.0;
  s.min_range_m = 2.5;  // beacon 1 (2 m, straight above) is too close: seed 004's 3.5-5 m band
  n = heard(tofs(s, 2.0));
  EXPECT_EQ(n.count(1), 0u);
  EXPECT_EQ(n[2], 5);
}

TEST(SimPhysics, ReceiversHearOnlyBeaconsWhoseBeamReachesThem) {
  Scenario s = still_world();
  // Beacon 2 is atan(3/2) = 56.3 degrees off its downward axis.
  s.beam_half_angle_rad = 60.0 * M_PI / 180.0;
  EXPECT_EQ(heard(tofs(s, 2.0)).count(2), 1u);
  s.beam_half_angle_rad = 50.0 * M_PI / 180.0;
  EXPECT_EQ(heard(tofs(s, 2.0)).count(2), 0u);
}

TEST(SimPhysics, TheTemperatureSetsTheSpeedOfSoundAndTheBeaconsReportIt) {
  Scenario s = still_world();
  s.temperature_c = 0.0;
  const double cold = tofs(s, 0.1).front().tof.tof_s;
  s.temperature_c = 30.0;
  const auto warm = tofs(s, 0.1).front();
  EXPECT_NEAR(cold / warm.tof.tof_s, speed_of_sound_mps(30.0) / speed_of_sound_mps(0.0), 1e-12);
  EXPECT_NEAR(warm.tof.tof_s, 2.0 / speed_of_sound_mps(30.0), 1e-12);
  EXPECT_EQ(warm.tof.beacon_temperature_c, 30.0);
  s.reported_temperature_c = 20.0;  // seed 002: what the beacons report is not the air's
  const auto misreported = tofs(s, 0.1).front();
  EXPECT_EQ(misreported.tof.beacon_temperature_c, 20.0);
  EXPECT_NEAR(misreported.tof.tof_s, warm.tof.tof_s, 1e-15);
}

TEST(SimPhysics, EchoesArriveLateByTheirExtraPath) {
  Scenario s = still_world();
  s.echo = {0.3, 0.5, 2.0};
  const double c = speed_of_sound_mps(s.temperature_c);
  const auto events = tofs(s, 400.0);
  int echoes = 0;
  for (const auto& e : events) {
    const double direct = (e.true_beacon_id == 1 ? 2.0 : std::sqrt(13.0)) / c;
    const double extra_m = (e.tof.tof_s - direct) * c;
    if (e.tof_is_echo) {
      ++echoes;
      EXPECT_GE(extra_m, 0.5 - 1e-9);
      EXPECT_LE(extra_m, 2.0 + 1e-9);
    } else {
      EXPECT_NEAR(extra_m, 0.0, 1e-9);
    }
  }
  const double n = static_cast<double>(events.size());
  EXPECT_NEAR(echoes / n, 0.3, 4.0 * std::sqrt(0.3 * 0.7 / n));
}

TEST(SimPhysics, SystematicWheelErrorsBiasTheOdometry) {
  Scenario s = still_world();
  s.odometry_k_v_m = 0.0;
  s.wheel_base_m = 0.4;
  s.trajectory = Trajectory({0.0, 0.0, 0.0}, {{100.0, 0.5, 0.25}}, false);  // v_R 0.55, v_L 0.45
  s.wheel_radius_error_right = 0.02;
  s.wheel_radius_error_left = -0.01;
  s.wheel_base_error = 0.05;
  SimSource source(s, 1);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(1.0), events);
  int checked = 0;
  for (const auto& e : events) {
    if (e.kind != SourceEvent::Kind::kOdometry) continue;
    EXPECT_NEAR(e.odometry.wheel_velocity_right_mps, 0.55 * 1.02, 1e-9);
    EXPECT_NEAR(e.odometry.wheel_velocity_left_mps, 0.45 * 0.99, 1e-9);
    EXPECT_NEAR(e.odometry.wheel_base_m, 0.42, 1e-12);
    ++checked;
  }
  EXPECT_EQ(checked, 100);
}

TEST(SimPhysics, VelocityNoiseFollowsSeed001Alphas) {
  // Straight at 0.5 m/s with alpha = [0.02, 0, 0.01, 0]: sigma_v^2 = 0.005, sigma_w^2 = 0.0025.
  Scenario s = still_world();
  s.wheel_base_m = 0.4;
  s.trajectory = Trajectory({0.0, 0.0, 0.0}, {{1000.0, 0.5, 0.0}}, false);
  s.odometry_alpha = std::array<double, 4>{0.02, 0.0, 0.01, 0.0};
  SimSource source(s, 9);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(200.0), events);
  double sum_v = 0, sum_vv = 0, sum_ww = 0;
  int n = 0;
  for (const auto& e : events) {
    if (e.kind != SourceEvent::Kind::kOdometry) continue;
    const auto& o = e.odometry;
    const double v = (o.wheel_velocity_right_mps + o.wheel_velocity_left_mps) / 2.0 - 0.5;
    const double w = (o.wheel_velocity_right_mps - o.wheel_velocity_left_mps) / o.wheel_base_m;
    sum_v += v;
    sum_vv += v * v;
    sum_ww += w * w;
    ++n;
  }
  EXPECT_NEAR(sum_v / n, 0.0, 5.0 * std::sqrt(0.005 / n));
  EXPECT_NEAR(sum_vv / n, 0.005, 0.05 * 0.005);
  EXPECT_NEAR(sum_ww / n, 0.0025, 0.05 * 0.0025);
}

TEST(SimPhysics, AnonymousPulsesCarryNoIdButTheMarkedOne) {
  Scenario s = still_world();
  s.identified = false;
  s.marked_beacon_id = 2;
  for (const auto& e : tofs(s, 2.0)) {
    EXPECT_EQ(e.tof.beacon_id, e.true_beacon_id == 2 ? 2u : kBeaconUnidentified);
  }
}

TEST(SimPhysics, LaserRaysAreCastOnTheMap) {
  Scenario s = still_world();
  s.trajectory = Trajectory({1.0, 1.0, M_PI / 2}, {{100.0, 0.0, 0.0}}, false);
  OccupancyGrid grid({0.0, 0.0}, 0.1, 40, 30);  // 4 m x 3 m room
  grid.fill_border();                           // inner faces at x 0.1, 3.9 and y 0.1, 2.9
  s.map = grid;
  LaserModel laser;
  laser.beams = 3;
  laser.fov_rad = M_PI;  // right, ahead, left of a robot facing +y
  laser.range_sigma_m = 0.0;
  laser.period_ns = 100 * kNsPerMillisecond;
  s.laser = laser;
  SimSource source(s, 1);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(0.25), events);
  int scans = 0;
  for (const auto& e : events) {
    if (e.kind != SourceEvent::Kind::kLaserScan) continue;
    ++scans;
    ASSERT_EQ(e.scan.ranges_m.size(), 3u);
    EXPECT_NEAR(e.scan.ranges_m[0], 2.9f, 1e-5);  // to the right: the wall at x = 3.9
    EXPECT_NEAR(e.scan.ranges_m[1], 1.9f, 1e-5);  // ahead: y = 2.9
    EXPECT_NEAR(e.scan.ranges_m[2], 0.9f, 1e-5);  // to the left: x = 0.1
    EXPECT_NEAR(e.scan.angle_min_rad, -M_PI / 2, 1e-6);
  }
  EXPECT_EQ(scans, 2);
}

TEST(SimPhysics, AWalkerGoesThereAndBackAtItsSpeed) {
  const Walker w({{0.0, 0.0}, {2.0, 0.0}, {2.0, 1.0}}, 0.5, 0.2);  // 3 m of path at 0.5 m/s
  EXPECT_TRUE(w.at(0.0).centre_m.isApprox(Eigen::Vector2d(0.0, 0.0)));
  EXPECT_TRUE(w.at(2.0).centre_m.isApprox(Eigen::Vector2d(1.0, 0.0)));
  EXPECT_TRUE(w.at(5.0).centre_m.isApprox(Eigen::Vector2d(2.0, 0.5)));
  EXPECT_TRUE(w.at(6.0).centre_m.isApprox(Eigen::Vector2d(2.0, 1.0)));   // the end: turns back
  EXPECT_TRUE(w.at(8.0).centre_m.isApprox(Eigen::Vector2d(2.0, 0.0)));
  EXPECT_TRUE(w.at(12.0).centre_m.isApprox(Eigen::Vector2d(0.0, 0.0)));  // back at the start
  EXPECT_TRUE(w.at(-1.0).centre_m.isApprox(Eigen::Vector2d(0.0, 0.0)));
  EXPECT_TRUE(w.at(std::nan("")).centre_m.allFinite());
  EXPECT_DOUBLE_EQ(w.at(1.0).radius_m, 0.2);
  // A zero-length leg within the path is walked through.
  const Walker z({{0.0, 0.0}, {1.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}}, 1.0, 0.2);
  EXPECT_TRUE(z.at(1.5).centre_m.isApprox(Eigen::Vector2d(1.0, 0.5)));
  EXPECT_THROW(Walker({{0.0, 0.0}, {0.0, 0.0}}, 1.0, 0.2), std::invalid_argument);
  EXPECT_THROW(Walker({{0.0, 0.0}}, 1.0, 0.2), std::invalid_argument);
}

TEST(SimPhysics, TheLaserSeesWalkersInFrontOfTheWallButNotOneItStandsIn) {
  OccupancyGrid room({0.0, 0.0}, 0.1, 40, 30);
  room.fill_border();  // the wall ahead (+x) at x = 3.9
  const Eigen::Vector2d from(1.0, 1.5);
  std::vector<Disc> people{{{2.5, 1.5}, 0.25}};
  EXPECT_NEAR(*first_surface_m(room, people, from, 0.0, 80.0), 1.25, 1e-9);       // the person's front
  EXPECT_NEAR(*first_surface_m(room, people, from, M_PI / 2, 80.0), 1.4, 1e-9);  // beside: the wall
  people.push_back({{1.0, 1.5}, 0.3});  // one where the scanner is: not seen
  EXPECT_NEAR(*first_surface_m(room, people, from, 0.0, 80.0), 1.25, 1e-9);
  EXPECT_FALSE(first_surface_m(room, {}, from, 0.0, 2.0));  // nothing within 2 m
}

TEST(SimPhysics, ASpotAcrossAnEdgeReadsAMixedPixelOrTheFirstEcho) {
  // A 4 m x 3 m room on 1 cm cells (walls' inner faces at x = 3.99, y = 2.99) and a box whose
  // face (x = 3.5) ends at y = 1.5: the beam along y = 1.5 straddles its edge.
  OccupancyGrid room({0.0, 0.0}, 0.01, 400, 300);
  room.fill_border();
  room.fill_rectangle({3.5, 0.0}, {3.6, 1.5});
  const Eigen::Vector2d from(0.5, 1.5);
  constexpr double kBoxM = 3.0, kWallM = 3.49;
  LaserSpot wide{0.013, 0.011, 0.5};  // the LMS5xx spot (laser_world.hpp), echoes within 0.5 m merge
  const double mixed = *spot_reading_m(room, {}, wide, from, 0.0, 80.0);
  EXPECT_GT(mixed, kBoxM + 0.05);  // between the box's face and the wall
  EXPECT_LT(mixed, kWallM - 0.05);
  wide.echo_merge_m = 0.1;  // echoes that do not merge: the first (the box) is read
  EXPECT_NEAR(*spot_reading_m(room, {}, wide, from, 0.0, 80.0), kBoxM, 0.01);
  // Away from any edge the spot reads what the ideal ray reads (the wall ahead, +y).
  EXPECT_NEAR(*spot_reading_m(room, {}, wide, from, M_PI / 2, 80.0), 1.49, 0.01);
  // The ideal ray reads one surface or the other, never between.
  const double axis = *spot_reading_m(room, {}, LaserSpot{}, from, 0.0, 80.0);
  EXPECT_TRUE(std::abs(axis - kBoxM) < 1e-9 || std::abs(axis - kWallM) < 1e-9) << axis;
}

}  // namespace
}  // namespace beaconloc::sim
