// The one input type (core/estimator_input.hpp): Estimator::push dispatches each kind to its
// method, the out-of-sequence fusion orders every kind by stamp_of, and the localizer core gives
// raw times of flight only to the estimators that use them, counting their rejections under
// "raw_tof.".
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/out_of_sequence_fusion.hpp"
#include "localizer_core.hpp"
#include "offline_run.hpp"
#include "sim/scenario_yaml.hpp"
#include "standing_odometry.hpp"

namespace beaconloc {
namespace {

// Writes down every call, in order: "odometry@<stamp>", "range@<stamp>", "laser@<stamp>",
// "raw_tof@<fire stamp>". Refuses a raw TOF of tof_s < 0 (negative_tof), as an estimator of raw
// TOFs would; takes laser scans and raw TOFs.
class RecordingEstimator : public Estimator {
 public:
  std::string name() const override { return "test_recording"; }
  void set_beacon_map(const BeaconMap&) override {}
  bool uses_laser() const override { return true; }
  BeaconInput beacon_input() const override { return BeaconInput::kRawTof; }
  InputResult predict(const OdometrySample& o) override { return note("odometry", o.stamp_ns); }
  InputResult update(const RangeMeasurement& r) override { return note("range", r.stamp_ns); }
  InputResult update_laser(const LaserScanSample& s) override { return note("laser", s.stamp_ns); }
  InputResult update_raw_tof(const RawTofSample& t) override {
    if (t.tof_s < 0.0) return InputResult::rejected(Rejection::kNegativeTof);
    return note("raw_tof", t.fire_stamp_ns);
  }
  std::optional<PoseEstimate> estimate() const override {
    PoseEstimate e;
    e.stamp_ns = static_cast<StampNs>(calls.size());  // changes with every call: a correction shows
    e.status = PoseStatus::kOk;
    return e;
  }
  PoseStatus status() const override { return PoseStatus::kOk; }
  std::optional<StartupWait> startup_wait() const override { return std::nullopt; }
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<RecordingEstimator>(*this); }

  std::vector<std::string> calls;

 private:
  InputResult note(const char* what, StampNs stamp_ns) {
    calls.push_back(std::string(what) + "@" + std::to_string(stamp_ns));
    return InputResult::ok();
  }
};

BEACONLOC_REGISTER_ESTIMATOR("test_recording", "test double: records the inputs it is pushed", "",
                             [](const EstimatorConfig&) { return std::make_unique<RecordingEstimator>(); });

OdometrySample odometry_at(StampNs stamp_ns) { return standing_odometry(stamp_ns); }
RangeMeasurement range_at(StampNs stamp_ns) {
  RangeMeasurement r;
  r.stamp_ns = stamp_ns;
  r.beacon_id = 7;
  r.range_m = 2.0;
  r.variance_m2 = 1e-4;
  return r;
}
LaserScanSample scan_at(StampNs stamp_ns) {
  LaserScanSample s;
  s.stamp_ns = stamp_ns;
  return s;
}
RawTofSample tof_fired_at(StampNs fire_stamp_ns, double tof_s = 0.006) {
  RawTofSample t;
  t.beacon_id = 9;
  t.fire_stamp_ns = fire_stamp_ns;
  t.tof_s = tof_s;
  return t;
}

TEST(EstimatorInput, PushGivesEachKindToItsMethod) {
  RecordingEstimator e;
  for (const EstimatorInput& in : std::vector<EstimatorInput>{odometry_at(1), range_at(2), scan_at(3), tof_fired_at(4)}) {
    EXPECT_TRUE(e.push(in).accepted);
  }
  EXPECT_EQ(e.calls, (std::vector<std::string>{"odometry@1", "range@2", "laser@3", "raw_tof@4"}));
  EXPECT_EQ(e.push(tof_fired_at(5, -1.0)).rejection, Rejection::kNegativeTof);
}

TEST(EstimatorInput, KindsAreNamedAndStampedOnce) {
  EXPECT_STREQ(kind_name(odometry_at(1)), "odometry");
  EXPECT_STREQ(kind_name(range_at(1)), "range");
  EXPECT_STREQ(kind_name(scan_at(1)), "laser");
  EXPECT_STREQ(kind_name(tof_fired_at(1)), "raw_tof");
  EXPECT_EQ(stamp_of(odometry_at(11)), 11);
  EXPECT_EQ(stamp_of(range_at(12)), 12);
  EXPECT_EQ(stamp_of(scan_at(13)), 13);
  EXPECT_EQ(stamp_of(tof_fired_at(14)), 14);  // the firing; the arrival needs the speed of sound
  PulseArrivalSample pulse;
  pulse.stamp_ns = 15;
  EXPECT_STREQ(kind_name(pulse), "pulse");
  EXPECT_EQ(stamp_of(pulse), 15);  // the arrival: there is no firing time
  EXPECT_TRUE(is_odometry(odometry_at(1)));
  EXPECT_FALSE(is_odometry(tof_fired_at(1)));
}

TEST(EstimatorInput, AnEstimatorOfDecodedRangesRefusesARawTof) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  const auto e = EstimatorRegistry::instance().create("range_ekf", config);
  EXPECT_EQ(e->beacon_input(), BeaconInput::kRanges);
  EXPECT_EQ(e->push(tof_fired_at(1)).rejection, Rejection::kRawTofUnused);
}

TEST(EstimatorInput, ALateRawTofIsReplayedAtItsStampAmongTheOtherKinds) {
  OutOfSequenceFusion fusion(std::make_unique<RecordingEstimator>());
  const StampNs ms = kNsPerMillisecond;
  for (StampNs t = 0; t <= 50 * ms; t += 10 * ms) ASSERT_TRUE(fusion.push(odometry_at(t)).accepted);
  ASSERT_TRUE(fusion.push(scan_at(45 * ms)).accepted);
  ASSERT_TRUE(fusion.push(tof_fired_at(25 * ms)).accepted);  // late: before the scan and two odometry samples
  ASSERT_TRUE(fusion.push(range_at(35 * ms)).accepted);
  const auto& calls = dynamic_cast<const RecordingEstimator&>(fusion.estimator()).calls;
  const std::vector<std::string> in_stamp_order{"odometry@0",        "odometry@10000000", "odometry@20000000",
                                                "raw_tof@25000000",  "odometry@30000000", "range@35000000",
                                                "odometry@40000000", "laser@45000000",    "odometry@50000000"};
  EXPECT_EQ(calls, in_stamp_order);
  EXPECT_EQ(fusion.push(tof_fired_at(-700 * ms)).rejection, Rejection::kTooLate);
}

TEST(EstimatorInput, TheLocalizerGivesRawTofsOnlyToEstimatorsThatUseThemAndThemNoRanges) {
  EstimatorConfig config;
  config.receivers = ReceiverArray::on_circle(0.19, 3);
  LocalizerCore raw("test_recording", config);
  ASSERT_EQ(raw.beacon_input(), BeaconInput::kRawTof);
  raw.on_odometry("r", odometry_at(0));
  EXPECT_TRUE(raw.on_raw_tof("r", tof_fired_at(5)).has_value());  // fused: the corrected pose goes out
  EXPECT_FALSE(raw.on_raw_tof("r", tof_fired_at(6, -1.0)).has_value());
  EXPECT_EQ(raw.counts().rejected("raw_tof.negative_tof"), 1u);
  // ... and never the decoder's ranges of the same pulses: each pulse reaches it once.
  EXPECT_FALSE(raw.on_range("r", range_at(7)).has_value());
  EXPECT_FALSE(raw.on_input("r", range_at(8)).has_value());
  EXPECT_EQ(raw.counts().accepted(), 2u);  // the odometry sample and the one good raw TOF

  LocalizerCore ranges("range_ekf", config);
  EXPECT_EQ(ranges.beacon_input(), BeaconInput::kRanges);
  ranges.on_odometry("r", odometry_at(0));
  EXPECT_FALSE(ranges.on_raw_tof("r", tof_fired_at(5)).has_value());  // never subscribed: never given one
  EXPECT_EQ(ranges.counts().rejected("raw_tof.raw_tof_unused"), 0u);
}

// Pulse arrivals (seed 002) reach only an estimator that hears the beacons that way, which is
// never given ranges or raw TOFs; the others never see a pulse (counted nowhere: not subscribed).
TEST(EstimatorInput, TheLocalizerGivesPulseArrivalsOnlyToEstimatorsThatHearThem) {
  EstimatorConfig config;
  config.receivers.receivers_base_m = {{0.0, 0.0}};
  LocalizerCore pulses("kleeman_iekf", config);
  ASSERT_EQ(pulses.beacon_input(), BeaconInput::kPulseArrivals);
  pulses.on_odometry("r", odometry_at(0));
  PulseArrivalSample before_sync;
  before_sync.stamp_ns = 5;
  before_sync.mark = PulseMark::kSingle;
  pulses.on_pulse("r", before_sync);
  pulses.on_range("r", range_at(7));
  pulses.on_raw_tof("r", tof_fired_at(8));
  // The pulse was given (and refused for its reason, under pulse.), the others not at all.
  EXPECT_EQ(pulses.counts().rejected("pulse.no_beacon_map"), 1u);
  EXPECT_EQ(pulses.counts().rejected_by_reason().size(), 1u);

  LocalizerCore ranges("range_ekf", config);
  ranges.on_odometry("r", odometry_at(0));
  ranges.on_pulse("r", before_sync);
  EXPECT_TRUE(ranges.counts().rejected_by_reason().empty());
}

// What an estimator holds beside the pose goes out with a pose once a second of data time, and
// only from estimators that have such state.
TEST(EstimatorInput, TheEstimatorStateGoesOutOnceASecondWithAPose) {
  const sim::Scenario s = sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed002_kleeman.yaml");
  EstimatorConfig config;
  config.receivers = s.receivers;
  LocalizerCore core("kleeman_iekf", config);
  core.set_beacon_map(BeaconMap(s.beacons));
  std::vector<StampNs> state_stamps;
  for (const SourceEvent& e : simulate(s, 1, 10.0)) {
    std::optional<LocalizerOutput> out;
    if (e.kind == SourceEvent::Kind::kOdometry) out = core.on_odometry("r", e.odometry);
    if (e.kind == SourceEvent::Kind::kPulse) out = core.on_pulse("r", e.pulse);
    if (!out || out->state.empty()) continue;
    state_stamps.push_back(out->estimate.stamp_ns);
    EXPECT_EQ(out->state.front().name, "speed_of_sound_mps");
    EXPECT_GT(out->state.front().sigma, 0.0);
  }
  ASSERT_GE(state_stamps.size(), 7u);  // from the first fix at ~2 s
  for (std::size_t i = 1; i < state_stamps.size(); ++i) {
    EXPECT_GE(state_stamps[i] - state_stamps[i - 1], kEstimatorStatePeriodNs);
    EXPECT_LT(state_stamps[i] - state_stamps[i - 1], kEstimatorStatePeriodNs + 20'000'000);
  }
  LocalizerCore ranges("range_ekf", config);
  ranges.set_beacon_map(BeaconMap(s.beacons));
  for (const SourceEvent& e : simulate(s, 1, 3.0)) {
    if (e.kind != SourceEvent::Kind::kOdometry) continue;
    if (auto out = ranges.on_odometry("r", e.odometry)) {
      EXPECT_TRUE(out->state.empty());
    }
  }
}

// A robot whose pulses missed their deadline is degraded; the next pulse makes it ok again, as a
// range does for the estimators of ranges.
TEST(EstimatorInput, APulseAfterAMissedDeadlineEndsTheSilence) {
  const sim::Scenario s = sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/seed002_kleeman.yaml");
  sim::Scenario moving = s;
  moving.trajectory = sim::Trajectory(Pose2(1.5, 1.5, 0.0), {{30.0, 0.25, 0.0}}, false);
  EstimatorConfig config;
  config.receivers = s.receivers;
  LocalizerCore core("kleeman_iekf", config);
  core.set_beacon_map(BeaconMap(s.beacons));
  bool silenced = false;
  std::optional<PoseStatus> after;
  for (const SourceEvent& e : simulate(moving, 1, 12.0)) {
    if (e.kind == SourceEvent::Kind::kOdometry) {
      if (auto out = core.on_odometry("r", e.odometry); out && silenced) after = out->estimate.status;
    }
    if (e.kind != SourceEvent::Kind::kPulse) continue;
    if (!silenced && ns_to_s(e.stamp_ns) > 8.0) {
      core.on_ranges_silent("r");
      ASSERT_EQ(core.worst_status(), PoseStatus::kDegraded);
      silenced = true;
      continue;
    }
    core.on_pulse("r", e.pulse);
  }
  ASSERT_TRUE(after);
  EXPECT_EQ(*after, PoseStatus::kOk);
}

}  // namespace
}  // namespace beaconloc
