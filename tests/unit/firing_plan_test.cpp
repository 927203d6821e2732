// Selective activation's core (seed 004 Sec. 3): a beacon's reach (slant range window and beam
// cone) as the simulator hears by it and the map carries it, the firing plan from a pose and its
// uncertainty, and the simulator firing the plan.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "beaconloc/core/firing_plan.hpp"
#include "sim/scenario_yaml.hpp"
#include "sim/sim_source.hpp"

namespace beaconloc {
namespace {

// Seed 004's SRF04: heard between 3.5 m and 5 m inside a 30 degree cone.
const BeaconReach kSrf04{3.5, 5.0, 30.0 * M_PI / 180.0};

TEST(BeaconReach, ValidOnlyForAWindowAndAConeOrNotKnownAtAll) {
  EXPECT_TRUE(kSrf04.valid());
  EXPECT_TRUE(BeaconReach{}.valid());
  EXPECT_FALSE(BeaconReach{}.known());
  for (const BeaconReach& bad : {BeaconReach{5.0, 3.5, 0.5}, BeaconReach{-1.0, 3.5, 0.5}, BeaconReach{0.0, 3.5, 0.0},
                                 BeaconReach{0.0, 3.5, 4.0}, BeaconReach{0.0, std::nan(""), 0.5},
                                 BeaconReach{0.0, 2e4, 0.5}, BeaconReach{1.0, 0.0, 0.0},
                                 BeaconReach{0.0, 3.0, std::numeric_limits<double>::infinity()}}) {
    EXPECT_FALSE(bad.valid()) << bad.min_range_m << " " << bad.max_range_m << " " << bad.beam_half_angle_rad;
  }
}

// at_drop, the floor annulus the plan tests against, says what reaches() says, point by point.
TEST(BeaconReach, TheFloorAnnulusAgreesWithReachesEverywhere) {
  const Eigen::Vector3d beacon(2.0, 1.0, 5.4);
  std::mt19937_64 rng(3);
  // Points below, level with and above the beacon; cones narrower and wider than pi/2.
  std::uniform_real_distribution<double> xy(-4.0, 8.0), z(0.0, 9.0);
  for (const BeaconReach& reach : {kSrf04, BeaconReach{0.0, 5.0, M_PI / 2}, BeaconReach{0.0, 8.0, 1.2},
                                   BeaconReach{0.5, 6.0, 2.2}, BeaconReach{0.0, 6.0, M_PI}}) {
    int heard = 0;
    for (int i = 0; i < 20000; ++i) {
      const Eigen::Vector3d p(xy(rng), xy(rng), z(rng));
      const BeaconReach::Annulus a = reach.at_drop(beacon.z() - p.z());
      const double foot = (p - beacon).head<2>().norm();
      const bool in_annulus = foot >= a.inner_m && foot <= a.outer_m;
      // Points on the boundary within 1e-9 may go either way.
      if (std::abs(foot - a.inner_m) < 1e-9 || std::abs(foot - a.outer_m) < 1e-9) continue;
      EXPECT_EQ(reach.reaches(beacon, p), in_annulus) << p.transpose();
      heard += in_annulus;
    }
    EXPECT_GT(heard, 100);
  }
  EXPECT_TRUE(BeaconReach{}.reaches(Eigen::Vector3d::Zero(), Eigen::Vector3d(1e5, 0.0, 0.0)));
}

TEST(BeaconMapReach, IsCheckedKeptAndComparedWithTheMap) {
  BeaconList list({{1, {0.0, 0.0, 5.4}, 0}, {2, {2.0, 0.0, 5.4}, 0}});
  list.reach[1] = kSrf04;
  const BeaconMap map(list);
  EXPECT_EQ(map.reach_of(1), kSrf04);
  EXPECT_FALSE(map.reach_of(2).known());
  EXPECT_EQ(map.list().reach.size(), 1u);
  BeaconList other = list;
  other.reach[2] = kSrf04;
  EXPECT_NE(BeaconMap(other), map);  // a beacon's reach changed: a new map
  other.reach[2] = BeaconReach{};
  EXPECT_EQ(BeaconMap(other), map);  // "not known" is not held: the same map
  BeaconList bad = list;
  bad.reach[2] = BeaconReach{0.0, std::nan(""), 0.5};
  EXPECT_EQ(check_beacons(bad).problem, BeaconMapProblem::kBadReach);
  EXPECT_EQ(check_beacons(bad).beacon_id, 2u);
  EXPECT_EQ(check_beacons(bad).describe(), "beacon 2: bad_reach");
  BeaconList stray = list;
  stray.reach[9] = kSrf04;
  EXPECT_EQ(check_beacons(stray).problem, BeaconMapProblem::kReachWithoutBeacon);
  RejectionCounter counts;
  EXPECT_FALSE(counted_beacon_map(stray, counts));
  EXPECT_EQ(counts.rejected("beacon_map.reach_without_beacon"), 1u);
}

ReceiverArray seed004_receivers() {
  ReceiverArray r;
  r.receivers_base_m = {{0.133, 0.0}, {-0.133, 0.0}};
  r.receiver_height_m = 1.0;
  return r;
}

BeaconMap grid_map() {
  BeaconList list;
  std::uint32_t id = 1;
  for (const double y : {0.3, 1.5, 2.7}) {
    for (const double x : {-0.5, 2.0, 4.5}) {
      list.map_frame.push_back({id, {x, y, 5.4}, 0});
      list.reach[id++] = kSrf04;
    }
  }
  return BeaconMap(list);
}

// A sure pose: exactly the beacons some receiver hears; an unsure one: more; one beyond every
// beacon's reach: all of them (never blind); a beacon of unknown reach: always.
TEST(FiringPlan, FiresWhatCanReachTheRobotWidenedByItsUncertainty) {
  const BeaconMap map = grid_map();
  const ReceiverArray receivers = seed004_receivers();
  const Pose2 pose(0.5, 0.5, 0.0);
  const Cov3 sure = 1e-6 * Cov3::Identity();
  const std::vector<std::uint32_t> plan = plan_firing(map, receivers, pose, sure);
  std::vector<std::uint32_t> hearing;
  map.for_each([&](const Beacon& b) {
    for (const auto& rx : receivers.receivers_base_m) {
      const Eigen::Vector2d p = transform_point(pose, rx);
      if (map.reach_of(b.id).reaches(b.position_map_m, {p.x(), p.y(), receivers.receiver_height_m})) {
        hearing.push_back(b.id);
        break;
      }
    }
  });
  EXPECT_EQ(plan, hearing);
  EXPECT_LT(plan.size(), map.size());
  EXPECT_FALSE(plan.empty());
  const std::vector<std::uint32_t> unsure = plan_firing(map, receivers, pose, 0.25 * Cov3::Identity());
  EXPECT_GT(unsure.size(), plan.size());
  for (const std::uint32_t id : plan) EXPECT_TRUE(std::count(unsure.begin(), unsure.end(), id)) << id;
  // An uncertain heading widens the receivers by their lever arm.
  Cov3 heading_only = 1e-6 * Cov3::Identity();
  heading_only(2, 2) = 4.0;
  EXPECT_GE(plan_firing(map, receivers, pose, heading_only).size(), plan.size());
  EXPECT_EQ(plan_firing(map, receivers, Pose2(50.0, 50.0, 0.0), sure), fire_all(map));
  BeaconList list = map.list();
  list.reach.erase(9);
  const std::vector<std::uint32_t> with_unknown = plan_firing(BeaconMap(list), receivers, pose, sure);
  EXPECT_TRUE(std::count(with_unknown.begin(), with_unknown.end(), 9u));
  // A pose or covariance that says nothing narrows nothing.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Cov3 broken = sure;
  broken(0, 0) = nan;
  EXPECT_EQ(plan_firing(map, receivers, pose, broken), fire_all(map));
  EXPECT_EQ(plan_firing(map, receivers, Pose2(nan, 0.5, 0.0), sure), fire_all(map));
  EXPECT_EQ(plan_firing(map, receivers, pose, sure, nan), fire_all(map));
  // Locally referenced beacons (seed 003, no map position): in every plan, and in fire_all.
  BeaconList with_local = map.list();
  with_local.group_frame.push_back({41, 7, {0.0, 0.0, 5.4}});
  const BeaconMap local_map(with_local);
  const std::vector<std::uint32_t> local_plan = plan_firing(local_map, receivers, pose, sure);
  EXPECT_TRUE(std::count(local_plan.begin(), local_plan.end(), 41u));
  EXPECT_EQ(local_plan.size(), plan.size() + 1);
  EXPECT_EQ(fire_all(local_map).size(), map.size() + 1);
}

sim::Scenario seed004() {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed004_two_receivers.yaml");
}

// The simulator fires the plan's beacons each in turn (ids it lacks never), every beacon again
// without a plan, and counts the slots fired and heard.
TEST(SimFiringPlan, FiresThePlanInTurnAndCountsTheSlotsHeard) {
  sim::SimSource sim(seed004(), 1);
  sim.set_firing_plan(std::vector<std::uint32_t>{5, 2, 77, 2});
  std::vector<SourceEvent> events;
  const StampNs slot_ns = sim.scenario().slot_period_ns;
  sim.advance(sim.scenario().first_slot_ns + 10 * slot_ns - 1, events);
  std::set<std::uint32_t> fired;
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kTof) fired.insert(e.true_beacon_id);
  }
  // The robot starts at (0.5, 0.5): generators 2 and 5 are both within its receivers' reach.
  EXPECT_EQ(fired, (std::set<std::uint32_t>{2, 5}));
  EXPECT_EQ(sim.firing_counts().fired, 10u);
  EXPECT_LE(sim.firing_counts().heard, sim.firing_counts().fired);
  sim.set_firing_plan(std::nullopt);
  events.clear();
  sim.advance(sim.scenario().first_slot_ns + 19 * slot_ns - 1, events);
  EXPECT_EQ(sim.firing_counts().fired, 19u);
  // An empty plan (or one of unknown ids only) is no plan: the firing order.
  sim.set_firing_plan(std::vector<std::uint32_t>{77});
  events.clear();
  sim.advance(sim.scenario().first_slot_ns + 28 * slot_ns - 1, events);
  std::set<std::uint32_t> all;
  for (const SourceEvent& e : events) {
    if (e.kind == SourceEvent::Kind::kTof) all.insert(e.true_beacon_id);
  }
  EXPECT_GT(all.size(), 1u);
}

}  // namespace
}  // namespace beaconloc
