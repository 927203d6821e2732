// range_ekf on the real recordings of ../shared/datasets (skipped without them), DDS-free: the
// replay fed straight into the decoder and localizer cores, as `beaconloc run --replay` wires
// them, with the README's settings. Issue 18's acceptance on them:
//  - TUC Labyrinth, full 933 s, the ranges' scale and bias learnt online (range_calibration 1):
//    position RMS <= 0.070 m (libRSF's self-tuning mixture gets 0.074 m), NEES in band >= 0.85;
//  - CMU Plaza 1 and 2 without --range-scale: the scale learnt within 1 % of the 1.069 the
//    datasets' README measured against ground truth, position RMS <= 0.45 m.
// Each with the settings of its sensors alone (issue 18's item 6, docs/replay-odometry-noise.md):
// the estimator's defaults, the ranges' calibration learnt, the noise the recording states (TUC's
// 0.1 m per range) or, where it states none, the noise its data fit best without ground truth.
// The README has the commands and figures; docs/range-calibration.md what they mean.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "beaconloc/core/estimator_parameters.hpp"
#include "evaluation.hpp"
#include "localizer_core.hpp"
#include "offline_run.hpp"
#include "replay/replay_source.hpp"

namespace beaconloc {
namespace {

const std::string kShared = std::string(BEACONLOC_SOURCE_DIR) + "/../shared/datasets";

struct ReplayRun {
  Metrics metrics;
  std::map<std::string, Estimator::StateValue> state;  // the newest of each value
};

ReplayRun replay(const std::string& path, const TofDecoderConfig& decoding, const ReplayOptions& options,
                 const std::vector<std::string>& parameters) {
  ReplaySource source(path, options);
  TofDecoder decoder(decoding);
  decoder.set_beacon_map(source.beacon_map());
  EstimatorConfig config;
  config.receivers = source.receivers();
  config.parameters = parse_estimator_parameters(parameters, "parameter");
  LocalizerCore localizer("range_ekf", config);
  localizer.set_beacon_map(source.beacon_map());
  std::vector<SourceEvent> events;
  source.advance(source.last_stamp_ns(), events);
  TruthTrack truth;
  std::vector<EstimateRow> rows;
  ReplayRun run;
  for (const SourceEvent& e : events) {
    if (e.has_truth) truth.add(e.stamp_ns, e.truth_map_base, e.truth_has_yaw);
    std::optional<EstimatorInput> input = estimator_input("robot", e, decoder, localizer.beacon_input());
    if (!input) continue;
    const bool odometry = is_odometry(*input);
    const auto out = localizer.on_input("robot", std::move(*input));
    if (!out || !odometry) continue;
    rows.push_back({"robot", out->estimate, "range_ekf"});
    for (const auto& v : out->state) run.state[v.name] = v;
  }
  run.metrics = evaluate(truth, rows);
  return run;
}

TEST(Recordings, TucLabyrinthWithTheRangesCalibratedOnline) {
  const std::string path = kShared + "/tuc_labyrinth_uwb/replay/full_933s";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no " << path;
  TofDecoderConfig decoding;
  decoding.max_range_m = 10.0;
  decoding.range_sigma_m = 0.1;
  ReplayOptions options;
  options.odometry_k_v_m = 0.0001;
  const ReplayRun r = replay(path, decoding, options, {"range_calibration=1"});
  ASSERT_GT(r.metrics.samples, 7000u);
  ASSERT_TRUE(r.state.count("range_scale") && r.state.count("range_bias_m"));
  std::printf("TUC Labyrinth full: position RMS %.4f m, NEES in band %.2f, scale %.4f +- %.4f, bias %.3f +- %.3f m\n",
              r.metrics.position_rms_m, r.metrics.nees_in_band_fraction, r.state.at("range_scale").value,
              r.state.at("range_scale").sigma, r.state.at("range_bias_m").value, r.state.at("range_bias_m").sigma);
  EXPECT_LE(r.metrics.position_rms_m, 0.070);
  EXPECT_GE(r.metrics.nees_in_band_fraction, 0.85);
  // Without the calibration, as before issue 18: 0.135 m, its covariance too small.
  const ReplayRun plain = replay(path, decoding, options, {});
  EXPECT_GT(plain.metrics.position_rms_m, 1.5 * r.metrics.position_rms_m);
}

// Issue 18, item 3: the ranges' noise learnt online (learn_range_noise) instead of taken as
// declared. Declared a third or three times what it is, a fixed noise leaves the covariance
// dishonest (too small) or the filter sluggish; learnt, both recordings localize as with their
// own sigma (within 10 % of its RMS), their covariance about as honest (NEES in band >= 0.8)
// (docs/range-noise.md).
TEST(Recordings, ARangeNoiseDeclaredWrongIsLearnt) {
  struct Case {
    const char* name;
    std::string path;
    double max_range_m, right_sigma_m, k_v, arw;
  };
  const std::vector<Case> cases = {
      {"TUC Labyrinth", kShared + "/tuc_labyrinth_uwb/replay/full_933s", 10.0, 0.1, 0.0001, 0.0},
      {"CMU Plaza 2", kShared + "/cmu_plaza_gpslam/replay/plaza2", 150.0, 0.55, 0.003, 0.014}};
  int replayed = 0;
  for (const Case& c : cases) {
    if (!std::filesystem::exists(c.path)) continue;
    ++replayed;
    ReplayOptions options;
    options.odometry_k_v_m = c.k_v;
    if (c.arw > 0.0) options.odometry_heading_arw_rad_per_sqrt_s = c.arw;
    const auto run_with = [&](double sigma_m, bool learn) {
      TofDecoderConfig decoding;
      decoding.max_range_m = c.max_range_m;
      decoding.range_sigma_m = sigma_m;
      std::vector<std::string> params = {"range_calibration=1"};
      if (learn) params.push_back("learn_range_noise=1");
      return replay(c.path, decoding, options, params);
    };
    const ReplayRun right = run_with(c.right_sigma_m, false);
    for (const double factor : {1.0 / 3.0, 3.0}) {
      const ReplayRun fixed = run_with(factor * c.right_sigma_m, false);
      const ReplayRun learnt = run_with(factor * c.right_sigma_m, true);
      ASSERT_GT(learnt.metrics.samples, 1000u) << c.name;
      ASSERT_TRUE(learnt.state.count("range_noise_scale")) << c.name;
      std::printf("%s, sigma declared %.3f m (its own %.2f m): fixed %.3f m RMS, NEES in band %.2f; learnt %.3f m, "
                  "%.2f, scale %.2f (sigma %.3f m); with its own sigma %.3f m, %.2f\n",
                  c.name, factor * c.right_sigma_m, c.right_sigma_m, fixed.metrics.position_rms_m,
                  fixed.metrics.nees_in_band_fraction, learnt.metrics.position_rms_m,
                  learnt.metrics.nees_in_band_fraction, learnt.state.at("range_noise_scale").value,
                  learnt.state.at("range_noise_scale").value * factor * c.right_sigma_m, right.metrics.position_rms_m,
                  right.metrics.nees_in_band_fraction);
      EXPECT_LE(learnt.metrics.position_rms_m, 1.10 * right.metrics.position_rms_m) << c.name << " x" << factor;
      EXPECT_GE(learnt.metrics.nees_in_band_fraction, 0.8) << c.name << " x" << factor;
      EXPECT_LT(learnt.metrics.position_rms_m, fixed.metrics.position_rms_m) << c.name << " x" << factor;
    }
  }
  if (replayed == 0) GTEST_SKIP() << "no recording beside the repository";
}

TEST(Recordings, CmuPlazaScaleLearntWithoutBeingGivenIt) {
  int replayed = 0;
  for (const char* name : {"plaza1", "plaza2"}) {
    const std::string path = kShared + "/cmu_plaza_gpslam/replay/" + name;
    if (!std::filesystem::exists(path)) continue;
    ++replayed;
    TofDecoderConfig decoding;
    decoding.max_range_m = 150.0;
    decoding.range_sigma_m = 0.55;  // the radios' and the mower's noise, fitted without ground truth
    ReplayOptions options;
    options.odometry_k_v_m = 0.003;
    options.odometry_heading_arw_rad_per_sqrt_s = 0.014;
    const ReplayRun r = replay(path, decoding, options, {"range_calibration=1"});
    ASSERT_GT(r.metrics.samples, 3000u) << name;
    ASSERT_TRUE(r.state.count("range_scale")) << name;
    const Estimator::StateValue& scale = r.state.at("range_scale");
    std::printf("%s: position RMS %.3f m, NEES in band %.2f, scale %.4f +- %.4f (the datasets' README: 1.069)\n", name,
                r.metrics.position_rms_m, r.metrics.nees_in_band_fraction, scale.value, scale.sigma);
    EXPECT_LT(std::abs(scale.value / 1.069 - 1.0), 0.01) << name;
    EXPECT_LE(r.metrics.position_rms_m, 0.45) << name;  // issue 18
    // And the calibration learnt brings the run to within 15 % of what the scale handed in (a
    // figure fitted against ground truth) gives: learning costs the first minutes, which weigh
    // most on the shorter Plaza 2 (409 s). Measured 3 % and 13 % (docs/range-calibration.md);
    // the bound was 10 % with the earlier noise settings, under which the scale handed in did
    // worse (in `run`, 0.405 m on Plaza 2 then, 0.365 m now) and the learnt run hardly
    // differently (0.430 m then).
    TofDecoderConfig given = decoding;
    given.range_scale = 1.069;
    const ReplayRun handed_in = replay(path, given, options, {});
    std::printf("%s with --range-scale 1.069: position RMS %.3f m\n", name, handed_in.metrics.position_rms_m);
    EXPECT_LT(r.metrics.position_rms_m, 1.15 * handed_in.metrics.position_rms_m) << name;
  }
  if (replayed == 0) GTEST_SKIP() << "no CMU Plaza recording beside the repository";
}

}  // namespace
}  // namespace beaconloc
