// The posterior Cramer-Rao bound of a scenario's pose (plugins/eval/offline/pose_bound.hpp):
//  - without ranges it is the dead reckoning's covariance, so the simulator's own odometry,
//    integrated over many seeds, has its spread (seed 000's k_v and seed 001's alpha): the
//    bound and the simulator take the same noise;
//  - ranges lower it, and echoes (left out) leave it higher at every stamp;
//  - its RMS is taken over the stamps scored, and none scored is no figure;
//  - the causes of error it does not model are refused with the reason.
// That the Kalman filter meets the recursion exactly on a linear-Gaussian model is pinned in
// posterior_crlb_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <stdexcept>

#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/range_model.hpp"
#include "offline_run.hpp"
#include "pose_bound.hpp"
#include "sim/scenario.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc {
namespace {

sim::Scenario without_beacons(sim::Scenario s, double duration_s) {
  s.beacons.clear();
  s.firing_order.clear();
  s.duration_s = duration_s;
  return s;
}

sim::Scenario seed001_odometry() {
  sim::Scenario s = sim::default_scenario();
  s.odometry_alpha = std::array<double, 4>{0.02, 0.02, 0.02, 0.02};  // seed 001 Table 3, case 3
  s.odometry_period_ns = 22 * kNsPerMillisecond;
  return s;
}

// The dead reckoning of the simulator's odometry from the true start, over many seeds: the
// sample covariance of its error at the end against the bound there.
void expect_dead_reckoning_spread_is_the_bound(const sim::Scenario& s) {
  constexpr int kRuns = 1000;
  const std::vector<PoseBoundSample> bound = pose_bound_trace(s, simulate(s, 1, s.duration_s));
  ASSERT_FALSE(bound.empty());
  const PoseBoundSample& end = bound.back();
  double position_sum = 0.0, heading_sum = 0.0;
  for (int run = 1; run <= kRuns; ++run) {
    Pose2 pose = s.trajectory.pose_at(0.0);
    StampNs last_ns = 0;
    for (const SourceEvent& e : simulate(s, static_cast<std::uint64_t>(run), s.duration_s)) {
      if (e.kind != SourceEvent::Kind::kOdometry) continue;
      pose = predict_diff_drive(pose, e.odometry.wheel_velocity_right_mps, e.odometry.wheel_velocity_left_mps,
                                e.odometry.wheel_base_m, ns_to_s(e.stamp_ns - last_ns))
                 .pose;
      last_ns = e.stamp_ns;
    }
    ASSERT_EQ(last_ns, end.stamp_ns);
    const Pose2 truth = s.trajectory.pose_at(ns_to_s(last_ns));
    position_sum += (pose.head<2>() - truth.head<2>()).squaredNorm();
    heading_sum += std::pow(wrap_angle_rad(pose.z() - truth.z()), 2);
  }
  // 1000 runs estimate a variance to about 5 % (sqrt(2 / 1000)); 15 % is three of those.
  EXPECT_NEAR(position_sum / kRuns / end.position_variance_m2, 1.0, 0.15)
      << "bound " << end.position_variance_m2 << " m^2";
  EXPECT_NEAR(heading_sum / kRuns / end.heading_variance_rad2, 1.0, 0.15)
      << "bound " << end.heading_variance_rad2 << " rad^2";
  std::printf("dead reckoning over %d runs, %.1f s: position %.3g m^2 (bound %.3g), heading %.3g rad^2 (bound %.3g)\n", kRuns,
              ns_to_s(end.stamp_ns), position_sum / kRuns, end.position_variance_m2, heading_sum / kRuns,
              end.heading_variance_rad2);
  EXPECT_GT(end.position_variance_m2, 1e-4);  // the test means something: the error has grown
}

TEST(PoseBound, WithoutRangesIsTheDeadReckoningSpreadOfSeed000Odometry) {
  expect_dead_reckoning_spread_is_the_bound(without_beacons(sim::default_scenario(), 6.0));
}

TEST(PoseBound, WithoutRangesIsTheDeadReckoningSpreadOfSeed001Odometry) {
  expect_dead_reckoning_spread_is_the_bound(without_beacons(seed001_odometry(), 6.0));
}

TEST(PoseBound, RangesLowerItAndEchoesLeftOutRaiseIt) {
  sim::Scenario clean = sim::default_scenario();
  clean.duration_s = 20.0;
  sim::Scenario echoes = clean;
  echoes.echo.probability = 0.3;
  const auto clean_bound = pose_bound_trace(clean, simulate(clean, 1, clean.duration_s));
  const auto echo_bound = pose_bound_trace(echoes, simulate(echoes, 1, echoes.duration_s));
  const auto blind = without_beacons(clean, clean.duration_s);
  const auto blind_bound = pose_bound_trace(blind, simulate(blind, 1, blind.duration_s));
  ASSERT_EQ(clean_bound.size(), echo_bound.size());
  ASSERT_EQ(clean_bound.size(), blind_bound.size());
  std::size_t echo_higher = 0;
  for (std::size_t i = 0; i < clean_bound.size(); ++i) {
    ASSERT_EQ(clean_bound[i].stamp_ns, echo_bound[i].stamp_ns);
    // Fewer ranges at the same points can only leave more (to rounding).
    EXPECT_GE(echo_bound[i].position_variance_m2, clean_bound[i].position_variance_m2 * (1.0 - 1e-9)) << i;
    EXPECT_GE(echo_bound[i].heading_variance_rad2, clean_bound[i].heading_variance_rad2 * (1.0 - 1e-9)) << i;
    EXPECT_LE(clean_bound[i].position_variance_m2, blind_bound[i].position_variance_m2 * (1.0 + 1e-9)) << i;
    echo_higher += echo_bound[i].position_variance_m2 > clean_bound[i].position_variance_m2 * 1.01;
  }
  EXPECT_GT(echo_higher, clean_bound.size() / 2);
  // Seed 000's ranges hold the position to about sigma_dd (1 cm) while dead reckoning drifts.
  EXPECT_LT(std::sqrt(clean_bound.back().position_variance_m2), 0.02);
  EXPECT_GT(blind_bound.back().position_variance_m2, 100.0 * clean_bound.back().position_variance_m2);
}

TEST(PoseBound, RmsIsOverTheStampsScoredAndNoneScoredIsNoFigure) {
  const std::vector<PoseBoundSample> trace{{10, 1.0, 0.01}, {20, 4.0, 0.04}, {30, 9.0, 0.09}};
  const auto two = pose_bound_rms(trace, {20, 30, 35});  // 35 is no odometry stamp: not counted
  ASSERT_TRUE(two);
  EXPECT_EQ(two->samples, 2u);
  EXPECT_NEAR(two->position_m, std::sqrt(6.5), 1e-12);
  EXPECT_NEAR(two->heading_deg, std::sqrt(0.065) * 180.0 / M_PI, 1e-9);
  EXPECT_FALSE(pose_bound_rms(trace, {}));
  EXPECT_FALSE(pose_bound_rms(trace, {15, 40}));
}

TEST(PoseBound, CausesOfErrorItDoesNotModelAreRefusedWithTheReason) {
  const auto refused = [](const std::function<void(sim::Scenario&)>& change, const char* reason) {
    sim::Scenario s = sim::default_scenario();
    s.duration_s = 1.0;
    change(s);
    const auto why = pose_bound_unsupported(s);
    ASSERT_TRUE(why) << reason;
    EXPECT_NE(why->find(reason), std::string::npos) << *why;
    EXPECT_THROW(pose_bound_trace(s, simulate(s, 1, s.duration_s)), std::invalid_argument);
    const PoseBoundResult r = pose_bound_of_run(s, {}, {1}, {false, true, false});
    EXPECT_FALSE(r.rms);
    EXPECT_EQ(r.unavailable, *why);
  };
  refused([](sim::Scenario& s) { s.radio_sync = false; }, "pulse arrivals");
  refused([](sim::Scenario& s) { s.local_group_frames_map[1] = Pose2::Zero(); }, "locally referenced");
  refused([](sim::Scenario& s) { s.wheel_radius_error_left = 0.01; }, "wheel");
  refused([](sim::Scenario& s) { s.wheel_base_error = -0.01; }, "wheel");
  refused([](sim::Scenario& s) { s.reported_temperature_c = s.temperature_c + 5.0; }, "temperature");
  refused([](sim::Scenario& s) { s.range_scale = 1.069; }, "ranging calibration");
  refused([](sim::Scenario& s) { s.range_bias_m = 0.1; }, "ranging calibration");
  sim::Scenario fine = sim::default_scenario();
  fine.reported_temperature_c = fine.temperature_c;
  EXPECT_FALSE(pose_bound_unsupported(fine));
}

TEST(PoseBound, ItsLineForRunGivesTheRatiosOrWhyNot) {
  PoseBoundResult r;
  r.rms = PoseBoundRms{0.01, 0.5, 100};
  Metrics m;
  m.samples = 100;
  m.position_rms_m = 0.012;
  m.heading_rms_deg = 0.6;
  EXPECT_NE(format_pose_bound(r, m).find("ours 1.20x and 1.20x"), std::string::npos) << format_pose_bound(r, m);
  m.samples = 99;  // the bound over other poses than those scored: no ratio
  EXPECT_NE(format_pose_bound(r, m).find("ours n/a (the bound covers other poses"), std::string::npos)
      << format_pose_bound(r, m);
  m.samples = 100;
  r.rms = PoseBoundRms{0.0, 0.0, 100};  // a noise-free scenario: no ratio, no inf
  EXPECT_NE(format_pose_bound(r, m).find("ours n/a (a zero bound"), std::string::npos) << format_pose_bound(r, m);
  EXPECT_EQ(format_pose_bound(r, m).find("inf"), std::string::npos);
  r.rms = PoseBoundRms{0.01, 0.5, 100};
  r.laser_fused = true;
  EXPECT_EQ(format_pose_bound(r, m).find("ours"), std::string::npos);
  EXPECT_NE(format_pose_bound(r, m).find("laser"), std::string::npos);
  PoseBoundResult none;
  none.unavailable = "because";
  EXPECT_NE(format_pose_bound(none, m).find("n/a (because)"), std::string::npos);
}

// A step the recursion refuses (no noise at all: a zero prior and exact ranges leave a zero
// innovation) is a reason, not an exception out of `accuracy` or `run`.
TEST(PoseBound, ARefusedStepIsAReasonNotACrash) {
  sim::Scenario s = sim::default_scenario();
  s.duration_s = 2.0;
  s.range_sigma_m = 0.0;
  s.odometry_k_v_m = 0.0;
  const std::vector<SourceEvent> events = simulate(s, 1, s.duration_s);
  EXPECT_THROW(pose_bound_trace(s, events), std::runtime_error);
  const PoseBoundResult r = pose_bound_of_run(s, events, {s_to_ns(1.0)}, {false, false, false});
  EXPECT_FALSE(r.rms);
  EXPECT_NE(r.unavailable.find("was refused"), std::string::npos) << r.unavailable;
}

// The range half of the noise the bound takes is the simulator's: a decoded range less the
// true distance from the beacon to the receiver at the pulse's arrival has range_variance_m2
// (range and arrival-time noise together).
TEST(PoseBound, RangeNoiseIsWhatTheSimulatorDraws) {
  sim::Scenario s = sim::default_scenario();
  s.duration_s = 60.0;
  s.tof_sigma_s = 3e-5;  // ~1 cm of arrival-time noise beside the 1 cm range noise
  TofDecoder decoder = scenario_decoder(s);
  std::map<std::uint32_t, Eigen::Vector3d> beacons;
  for (const Beacon& b : s.beacons) beacons[b.id] = b.position_map_m;
  double sum = 0.0, sum_sq = 0.0;
  std::size_t n = 0;
  for (const SourceEvent& e : simulate(s, 1, s.duration_s)) {
    if (e.kind != SourceEvent::Kind::kTof) continue;
    const auto out = decoder.decode("robot", e.tof);
    ASSERT_TRUE(out.range);
    const double distance = predict_range(s.trajectory.pose_at(ns_to_s(e.stamp_ns)),
                                          s.receivers.receivers_base_m[e.tof.receiver_id],
                                          s.receivers.receiver_height_m, beacons.at(e.true_beacon_id))
                                .range_m;
    const double error = out.range->range.range_m - distance;
    sum += error;
    sum_sq += error * error;
    ++n;
  }
  ASSERT_GT(n, 500u);
  const double mean = sum / static_cast<double>(n);
  const double variance = sum_sq / static_cast<double>(n) - mean * mean;
  EXPECT_NEAR(variance / sim::range_variance_m2(s), 1.0, 0.15) << n << " ranges";  // sqrt(2 / n) < 6 %
  EXPECT_LT(std::abs(mean), 3.0 * std::sqrt(sim::range_variance_m2(s) / static_cast<double>(n)));
}

}  // namespace
}  // namespace beaconloc
