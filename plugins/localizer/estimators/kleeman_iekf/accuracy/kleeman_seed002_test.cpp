// kleeman_iekf on the seed 002 setup (examples/scenarios/seed002_kleeman.yaml) over ten seeds,
// against the paper's Sec. 4 and the simulator's truth (release builds only: about 2 s there).
// docs/accuracy-seed002.md has the figures and the commands that print them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "beaconloc/core/bounds/posterior_crlb.hpp"
#include "beaconloc/core/models/arrival_time_model.hpp"
#include "beaconloc/core/models/diff_drive_motion.hpp"
#include "beaconloc/core/models/linear_motion.hpp"
#include "beaconloc/core/speed_of_sound.hpp"
#include "kleeman_iekf/kleeman_iekf.hpp"
#include "offline_run.hpp"
#include "sim/faults.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc {
namespace {

constexpr int kSeeds = 10;

sim::Scenario seed002() {
  return sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed002_kleeman.yaml");
}

double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

struct Figures {
  std::vector<double> path_std, path_max, position_rms, heading_rms, nees;
};

Figures over_seeds(const sim::Scenario& s, const std::vector<std::string>& params) {
  Figures f;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const OfflineRunResult r = run_scenario_offline(s, seed, "kleeman_iekf", params);
    EXPECT_GT(r.metrics.samples, 10000u) << "seed " << seed;  // 112 s of 100 Hz poses scored
    if (!r.metrics.path_error_std_m || !r.metrics.heading_rms_deg) {
      ADD_FAILURE() << "seed " << seed << ": no path error";
      continue;
    }
    f.path_std.push_back(*r.metrics.path_error_std_m);
    f.path_max.push_back(*r.metrics.path_error_max_m);
    f.position_rms.push_back(r.metrics.position_rms_m);
    f.heading_rms.push_back(*r.metrics.heading_rms_deg);
    f.nees.push_back(r.metrics.nees_in_band_fraction);
  }
  return f;
}

// Sec. 4: "a standard deviation in path error from 20 seconds until 120 seconds of 40 mm", "the
// maximum error is limited to 100 mm". The path error's standard deviation meets the paper's; the
// covariance is honest. Its maximum does NOT meet the paper's 100 mm (0.109 m on average, 0.145 m
// at worst): the lateral error follows the heading error, and the heading random-walks with the
// scenario's odometry noise (seed 000's k_v = 4e-4 m, an assumption: 0.011 rad a slot), which the
// beacons' 7 cm a pulse correct slowly. The filter's path error RMS is 1.05 times the posterior
// Cramer-Rao bound's sigma across the path, 36 mm (AgainstThePosteriorCramerRaoBound), and 100 mm
// is 2.8 of those. The 0.125 m below is a guard against regressions at today's figure.
TEST(KleemanOnSeed002, PathErrorMeetsThePapersStandardDeviationWithAnHonestCovariance) {
  const Figures f = over_seeds(seed002(), {});
  ASSERT_EQ(f.path_std.size(), static_cast<std::size_t>(kSeeds));
  std::printf("seed 002, %d seeds: path error std %.4f m (paper 0.040), max %.4f m mean, %.4f m largest (paper 0.100), "
              "E_p RMS %.4f m, E_phi RMS %.2f deg, NEES in band %.2f\n",
              kSeeds, mean_of(f.path_std), mean_of(f.path_max), *std::max_element(f.path_max.begin(), f.path_max.end()),
              mean_of(f.position_rms), mean_of(f.heading_rms), mean_of(f.nees));
  EXPECT_LE(mean_of(f.path_std), 0.040);
  EXPECT_LE(mean_of(f.path_max), 0.125);
  EXPECT_GE(*std::min_element(f.nees.begin(), f.nees.end()), 0.80);
}

// The filter's state over a run, sampled at the odometry steps.
struct Trace {
  std::vector<double> t_s, speed_of_sound_mps, speed_of_sound_sigma_mps, cycle_s, fire_time_error_s;
  std::size_t misnamed = 0;  // filter slots whose beacon is not the one that fired then
  std::uint64_t losses = 0;
};

Trace trace(const sim::Scenario& s, std::uint64_t seed, const std::vector<std::string>& params) {
  OfflineStack stack(s, "kleeman_iekf", parse_estimator_parameters(params, "param"));
  Trace out;
  for (const SourceEvent& e : simulate(s, seed, s.duration_s)) {
    stack.feed("robot", e);
    if (e.kind != SourceEvent::Kind::kOdometry) continue;
    const auto* k = dynamic_cast<const KleemanIekf*>(stack.localizer.estimator("robot"));
    if (!k || !k->filter_state()) continue;
    const kleeman::State x = *k->filter_state();
    const double fire_s = x(kleeman::kFireTime) + ns_to_s(*k->epoch_ns());
    // The truth: the scenario fires slot k at first_slot + k T.
    const double period = ns_to_s(s.slot_period_ns), first = ns_to_s(s.first_slot_ns);
    out.t_s.push_back(ns_to_s(e.stamp_ns));
    out.speed_of_sound_mps.push_back(x(kleeman::kSpeedOfSound));
    out.speed_of_sound_sigma_mps.push_back(std::sqrt((*k->filter_covariance())(kleeman::kSpeedOfSound, kleeman::kSpeedOfSound)));
    out.cycle_s.push_back(x(kleeman::kCycle));
    const double firing = std::round((fire_s - first) / period);
    out.fire_time_error_s.push_back(fire_s - (first + firing * period));
    const auto fired = s.firing_order[static_cast<std::size_t>(firing) % s.firing_order.size()];
    if (k->current_beacon() != fired) ++out.misnamed;
    out.losses = k->losses();
  }
  return out;
}

// Sec. 4, Fig. 8: three initial speeds of sound (standard deviation 5 m/s) converge on one value.
// Here from 5 m/s below and above the truth (26 C: 346.8 m/s) and from the nominal 20 C the
// estimator assumes (343.3 m/s): at the end each lies within three of its own standard deviations
// of the truth, the three within 0.5 m/s of one another. (How close to the truth they come is
// what the data allow: the posterior Cramer-Rao bound is 0.55 m/s after 132 s here,
// AgainstThePosteriorCramerRaoBound.)
TEST(KleemanOnSeed002, TheSpeedOfSoundConvergesFromEitherSideAndFromTheNominalTemperature) {
  const sim::Scenario s = seed002();
  const double truth = speed_of_sound_mps(s.temperature_c);
  std::vector<double> errors;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    std::vector<double> ends;
    for (const double initial : {truth - 5.0, truth + 5.0, speed_of_sound_mps(20.0)}) {
      const Trace t = trace(s, seed, {"initial_speed_of_sound_mps=" + std::to_string(initial)});
      ASSERT_FALSE(t.t_s.empty());
      const double end = t.speed_of_sound_mps.back(), sigma = t.speed_of_sound_sigma_mps.back();
      EXPECT_LT(std::abs(end - truth), 3.0 * sigma) << "seed " << seed << " from " << initial;
      EXPECT_LT(sigma, 1.0) << "seed " << seed;
      ends.push_back(end);
      errors.push_back(std::abs(end - truth));
    }
    EXPECT_LT(*std::max_element(ends.begin(), ends.end()) - *std::min_element(ends.begin(), ends.end()), 0.5)
        << "seed " << seed;
  }
  std::printf("speed of sound after %.0f s, %d seeds x 3 starts: mean |error| %.2f m/s, largest %.2f m/s\n",
              s.duration_s, kSeeds, mean_of(errors), *std::max_element(errors.begin(), errors.end()));
}

// The posterior Cramer-Rao bound (core/bounds/posterior_crlb.hpp) of seed 002's estimation
// along the simulator's true path, from the simulator's own noise models: the odometry's wheel
// noise (k_v at the true wheel speeds) as the robot's process noise, each direct pulse's arrival
// time (0.2 ms; echoes not fed: recognised, as the bound assumes), T, t0 and s constant unknowns,
// slot k fired at t0 + k T. On the state of eq. 14 with v held known (a nuisance made known only
// lowers a bound): [x, y, v, theta, T, t0, s].
// Priors: what the estimator is told beforehand (T's and s's sigmas, KleemanParameters), for
// the rest next to nothing (the position anywhere in 10 m, the heading any, t0 anywhere in a slot).
struct BoundTrace {
  std::vector<double> t_s, cross_track_sigma_m, heading_sigma_rad, speed_of_sound_sigma_mps;
};

// Root mean square of a sigma over the scored poses (t_s >= from_s).
double rms_from(const std::vector<double>& t_s, const std::vector<double>& sigma, double from_s) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    if (t_s[i] < from_s) continue;
    sum += sigma[i] * sigma[i];
    ++n;
  }
  return n ? std::sqrt(sum / static_cast<double>(n)) : std::nan("");
}

BoundTrace seed002_bound(const sim::Scenario& s, std::uint64_t seed) {
  using namespace kleeman;
  const KleemanParameters told;
  const double c = speed_of_sound_mps(s.temperature_c);
  const double period = ns_to_s(s.slot_period_ns), first = ns_to_s(s.first_slot_ns);
  const double dt = ns_to_s(s.odometry_period_ns);
  EXPECT_EQ(s.receivers.size(), 1u);  // eq. 21: one receiver at the robot's origin
  EXPECT_TRUE(s.receivers.receivers_base_m[0].isZero());
  EXPECT_FALSE(s.odometry_alpha);  // the wheel noise is seed 000's k_v
  Covariance prior = Covariance::Zero();
  prior(kX, kX) = prior(kY, kY) = 10.0 * 10.0;
  prior(kHeading, kHeading) = M_PI * M_PI / 3.0;  // uniform on a turn
  prior(kCycle, kCycle) = told.slot_period_sigma_s * told.slot_period_sigma_s;
  prior(kFireTime, kFireTime) = period * period / 12.0;  // uniform over a slot
  prior(kSpeedOfSound, kSpeedOfSound) = told.initial_speed_of_sound_sigma_mps * told.initial_speed_of_sound_sigma_mps;
  PosteriorCrlb<kStateSize> bound(prior);
  std::int64_t slot = 0;  // the slot whose firing t0 is
  const auto truth_at = [&](double t) {
    const Pose2 p = s.trajectory.pose_at(t);
    State x = State::Zero();
    x(kX) = p.x();
    x(kY) = p.y();
    x(kHeading) = p.z();
    x(kCycle) = period;
    x(kFireTime) = first + period * static_cast<double>(slot);
    x(kSpeedOfSound) = c;
    return x;
  };
  // t0(k+1) = t0(k) + T: no noise, the firing is the cycle's.
  Covariance next_slot = Covariance::Identity();
  next_slot(kFireTime, kCycle) = 1.0;
  const LinearMotion<kStateSize, 1> slot_step(next_slot, Vec<kStateSize>::Zero(), Mat<1, 1>::Zero(),
                                              Covariance::Zero());
  const BeaconMap map(s.beacons);
  BoundTrace out;
  std::size_t refused = 0, pulses = 0;
  for (const SourceEvent& e : simulate(s, seed, s.duration_s)) {
    const double t = ns_to_s(e.stamp_ns);
    if (e.kind == SourceEvent::Kind::kOdometry) {
      double v = 0.0, w = 0.0;
      s.trajectory.mean_velocity(t - dt, t, v, w);
      const Eigen::Vector2d wheels_true(v + w * s.wheel_base_m / 2.0, v - w * s.wheel_base_m / 2.0);
      // The simulator's sigma_v^2 = k_v |v| / dT per wheel, at the true speeds (it reports it at
      // the measured ones).
      const Eigen::Matrix2d wheel_noise = (s.odometry_k_v_m / dt * wheels_true.cwiseAbs()).asDiagonal();
      const DiffDriveMotion motion(s.wheel_base_m, wheel_noise, {kX, kY, kHeading});
      refused += bound.predict(motion, truth_at(t - dt), wheels_true, dt) != FilterOutcome::kApplied;
      const Covariance& p = bound.covariance();
      const double yaw = s.trajectory.pose_at(t).z();
      const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw));
      out.t_s.push_back(t);
      out.cross_track_sigma_m.push_back(std::sqrt(across.dot(p.block<2, 2>(kX, kX) * across)));
      out.heading_sigma_rad.push_back(std::sqrt(p(kHeading, kHeading)));
      out.speed_of_sound_sigma_mps.push_back(std::sqrt(p(kSpeedOfSound, kSpeedOfSound)));
    } else if (e.kind == SourceEvent::Kind::kPulse && !e.tof_is_echo) {
      // A pulse carries no firing time: its slot is the one it arrives in, every flight (under
      // 20 m, 58 ms) being shorter than a slot (150 ms).
      const auto fired = static_cast<std::int64_t>(std::floor((t - first) / period));
      for (; slot < fired; ++slot) refused += bound.predict(slot_step, truth_at(t), Vec<1>::Zero(), period) != FilterOutcome::kApplied;
      EXPECT_EQ(s.firing_order[static_cast<std::size_t>(fired) % s.firing_order.size()], e.true_beacon_id);
      const ArrivalTimeModel model(map.find(e.true_beacon_id)->position_map_m, s.receivers.receiver_height_m,
                                   s.tof_sigma_s * s.tof_sigma_s, arrival_time_index());
      refused += bound.update(model, truth_at(t)) != FilterOutcome::kApplied;
      ++pulses;
    }
  }
  EXPECT_EQ(refused, 0u);
  EXPECT_GT(static_cast<double>(slot), 0.99 * (s.duration_s - first) / period);  // every slot stepped
  EXPECT_GT(pulses, 800u);
  return out;
}

// The filter against the bound, seed by seed (issue 18's measure, here for seed 002): the path
// error beside the bound's sigma across the path, the heading, and the speed of sound at the end.
// An estimator at the bound has a ratio of 1; above 1 is what it leaves on the table. The bound
// is what says the "within 0.5 m/s on every seed" is out of any estimator's reach here,
// and what the path error's maximum should be read against.
TEST(KleemanOnSeed002, AgainstThePosteriorCramerRaoBound) {
  const sim::Scenario s = seed002();
  const double truth = speed_of_sound_mps(s.temperature_c);
  std::vector<double> path_rms, heading_rms, bound_cross, bound_heading, bound_sound, sound_error_sq, path_max_in_sigmas;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const BoundTrace b = seed002_bound(s, seed);
    ASSERT_FALSE(b.t_s.empty());
    const double cross = rms_from(b.t_s, b.cross_track_sigma_m, s.score_from_s);
    const double heading = rms_from(b.t_s, b.heading_sigma_rad, s.score_from_s);
    const OfflineRunResult r = run_scenario_offline(s, seed, "kleeman_iekf", {});
    ASSERT_TRUE(r.metrics.path_error_rms_m && r.metrics.heading_rms_deg);
    EXPECT_GT(*r.metrics.path_error_rms_m, 0.8 * cross) << "seed " << seed << ": well below the bound";
    path_rms.push_back(*r.metrics.path_error_rms_m);
    heading_rms.push_back(*r.metrics.heading_rms_deg * M_PI / 180.0);
    path_max_in_sigmas.push_back(*r.metrics.path_error_max_m / cross);
    bound_cross.push_back(cross);
    bound_heading.push_back(heading);
    bound_sound.push_back(b.speed_of_sound_sigma_mps.back());
    const Trace t = trace(s, seed, {});
    ASSERT_FALSE(t.t_s.empty());
    sound_error_sq.push_back((t.speed_of_sound_mps.back() - truth) * (t.speed_of_sound_mps.back() - truth));
  }
  const double sound_bound = mean_of(bound_sound), sound_rms = std::sqrt(mean_of(sound_error_sq));
  // Ratios of root mean squares over the seeds: the filter's error against the bound's sigma.
  const auto rms = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x * x;
    return std::sqrt(sum / static_cast<double>(v.size()));
  };
  const double path_ratio = rms(path_rms) / rms(bound_cross), heading_ratio = rms(heading_rms) / rms(bound_heading);
  // An estimator with a Gaussian error at the bound is within 0.5 m/s on one seed with this chance.
  const double within = std::erf(0.5 / (sound_bound * std::sqrt(2.0)));
  std::printf("bound, %d seeds: across the path %.4f m RMS from %.0f s, the filter's path error %.4f m RMS (ratio %.2f); "
              "heading %.2f deg, the filter's %.2f deg (ratio %.2f); path error max %.1f bound sigmas (mean)\n",
              kSeeds, rms(bound_cross), s.score_from_s, rms(path_rms), path_ratio, rms(bound_heading) * 180.0 / M_PI,
              rms(heading_rms) * 180.0 / M_PI, heading_ratio, mean_of(path_max_in_sigmas));
  std::printf("bound on the speed of sound after %.0f s: %.3f m/s; the filter's RMS error %.3f m/s (ratio %.2f); "
              "an estimator at the bound is within 0.5 m/s on one seed with p = %.2f, on all %d with p = %.3f\n",
              s.duration_s, sound_bound, sound_rms, sound_rms / sound_bound, within, kSeeds, std::pow(within, kSeeds));
  EXPECT_LT(path_ratio, 1.25);  // issue 18's 1.25x of the bound
  EXPECT_LT(heading_ratio, 1.25);
  EXPECT_LT(sound_rms / sound_bound, 1.25);
}

// T and t0 (eq. 14) converge, from a cycle 1.2 ms (1.2 of its prior sigmas) longer than the
// nominal 150 ms the estimator assumes: T to 1.5 us of the truth and t0 to 0.3 ms (1.5 sigma of
// one arrival) from 30 s on, and every slot's beacon named as the one that fired.
TEST(KleemanOnSeed002, CycleTimeAndFiringTimeConvergeFromAnOffNominalCycle) {
  sim::Scenario s = seed002();
  s.slot_period_ns = 151'200'000;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const Trace t = trace(s, seed, {});
    double worst_cycle = 0.0, worst_fire = 0.0;
    for (std::size_t i = 0; i < t.t_s.size(); ++i) {
      if (t.t_s[i] < 30.0) continue;
      worst_cycle = std::max(worst_cycle, std::abs(t.cycle_s[i] - ns_to_s(s.slot_period_ns)));
      worst_fire = std::max(worst_fire, std::abs(t.fire_time_error_s[i]));
    }
    EXPECT_LT(worst_cycle, 1.5e-6) << "seed " << seed;
    EXPECT_LT(worst_fire, 3e-4) << "seed " << seed;
    EXPECT_EQ(t.misnamed, 0u) << "seed " << seed;
    EXPECT_EQ(t.losses, 0u) << "seed " << seed;
  }
}

// Sec. 3.9: echoes are gated out. The scenario's 5 % doubled: no seed diverges (every pose from
// 20 s within 0.5 m of the path, the line past which every estimator counts as not localized,
// accuracy/every_estimator_test.cpp), and the path error's standard deviation stays within 10 mm
// of the clean run's; a silence of 2 s (every pulse in 13 slots missed) is survived too. (An echo
// just over the gate still gets in now and then: one seed's worst pose under 10 % echoes is 0.32 m
// off for a second, docs/accuracy-seed002.md.)
TEST(KleemanOnSeed002, TenPercentEchoesAndTwoSecondsWithoutPulsesAreSurvived) {
  const sim::Scenario clean = seed002();
  sim::Scenario echoes = clean;
  echoes.echo.probability = 0.10;
  sim::Scenario outage = clean;
  sim::apply_fault(outage, "tof_outage=60:62");
  for (const sim::Scenario* s : {&echoes, &outage}) {
    std::vector<double> path_std, baseline;
    std::uint64_t gated = 0;
    for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
      const OfflineRunResult r = run_scenario_offline(*s, seed, "kleeman_iekf", {});
      ASSERT_TRUE(r.metrics.path_error_std_m);
      path_std.push_back(*r.metrics.path_error_std_m);
      baseline.push_back(*run_scenario_offline(clean, seed, "kleeman_iekf", {}).metrics.path_error_std_m);
      EXPECT_LT(*r.metrics.path_error_max_m, 0.5) << "seed " << seed;
      gated += r.rejections.rejected("localizer.pulse.gated_nis");
    }
    std::printf("%s: path error std %.4f m (clean %.4f m), pulses gated %llu\n", s == &echoes ? "10 % echoes" : "2 s outage",
                mean_of(path_std), mean_of(baseline), static_cast<unsigned long long>(gated));
    EXPECT_LT(mean_of(path_std), mean_of(baseline) + 0.010);
    if (s == &echoes) {
      EXPECT_GT(gated, 500u);  // 10 % of 880 pulses a run over ten seeds, most of them gated
    }
  }
}

}  // namespace
}  // namespace beaconloc
