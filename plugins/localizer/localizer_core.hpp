#pragma once
// The localizer without DDS: one estimator instance per robot id, created on the robot's first
// sample, and the counts of what was accepted and refused. The participant only converts.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/core/firing_plan.hpp"
#include "beaconloc/core/out_of_sequence_fusion.hpp"
#include "beaconloc/core/rejection_counter.hpp"

namespace beaconloc {

struct LocalizerOutput {
  std::string robot_id;
  PoseEstimate estimate;
  std::vector<std::uint32_t> beacons_used;  // beacons fused since the previous output
  // The estimator's state beside the pose (Estimator::state_values), once per
  // kEstimatorStatePeriodNs of the robot's data time; empty between, and for most estimators.
  std::vector<Estimator::StateValue> state;
};

// How often a robot's estimator state goes out: a second of data time (plots over minutes, as
// seed 002's Fig. 8; a hundred times fewer samples than the poses).
inline constexpr StampNs kEstimatorStatePeriodNs = 1'000'000'000;

// Why the robots without a pose have none: how many wait for each start-up condition, and the
// first of them (by robot id) with the numbers that matter. Short for many robots.
struct StartupSummary {
  std::map<StartupCondition, std::size_t> robots_by_condition;
  std::string first_robot;
  StartupWait first_wait;
  bool empty() const { return robots_by_condition.empty(); }
  // "2 initializing: too_few_beacons 1, mirror_ambiguous 1 (robot a: 2 of 3 beacons heard)"
  std::string describe() const;
};

class LocalizerCore {
 public:
  // Throws UnknownEstimator when no estimator has that name. An empty robot_filter serves
  // every robot on the topics; otherwise samples of other robots are ignored (and counted).
  LocalizerCore(std::string estimator_name, EstimatorConfig config, std::string robot_filter = {});

  // A beacon map as received (the bus): refused whole, counted as beacon_map.<reason>, when
  // check_beacons refuses it; the map in use is kept then. Returns whether it was taken.
  bool on_beacon_map(const BeaconList& beacons);
  // The first map is given to every robot's estimator; the same map again (a restarted gateway)
  // changes nothing; a different one (beacons moved, added or gone) restarts every robot on it:
  // what an estimator holds was measured against the old beacons (restart_robot).
  void set_beacon_map(const BeaconMap& map);
  bool has_beacon_map() const { return !map_.empty(); }
  const BeaconMap& beacon_map() const { return map_; }
  std::uint64_t beacon_map_changes() const { return beacon_map_changes_; }
  // The site's beacon calibration (seed 003: locally referenced groups calibrated by a robot),
  // gathered from every source: a calibration received (the BeaconCalibration topic, a file) and
  // what the robots it serves find. A group's better calibration replaces the one held
  // (merge_calibration: the surer beacons; every localizer keeps the same). It is given to every
  // robot's estimator, at once and whenever one is made or restarted (not back to the robot that
  // found it): a robot localizes in the groups others calibrated without a calibration drive of
  // its own. Refused and counted as calibration.<problem>: a calibration check_calibration
  // refuses (whole); a group that would put a beacon in two groups, or that does not fit the map
  // (calibration_fitting: calibration.not_on_map). Groups received before the first map are kept
  // until it comes; a map drops those that do not fit it. An estimator that uses no calibration
  // takes none (false). Returns whether the site's calibration changed.
  bool on_calibration(const BeaconCalibration& calibration);
  const BeaconCalibration& calibration() const { return calibration_; }
  bool uses_calibration() const { return uses_calibration_; }  // its estimator's (Estimator::uses_calibration)
  // Counts the changes of calibration(): the participant publishes and keeps it when it moved.
  std::uint64_t calibration_revision() const { return calibration_revision_; }
  // Any input: odometry to on_odometry; a range, scan or raw TOF fused at its stamp (nothing for
  // a kind the estimator does not take: see on_range, on_laser, on_raw_tof).
  std::optional<LocalizerOutput> on_input(const std::string& robot_id, EstimatorInput input);
  // Predicts; returns the pose to publish once the robot's estimator has one.
  std::optional<LocalizerOutput> on_odometry(const std::string& robot_id, const OdometrySample& odometry);
  // Corrects; returns the corrected pose when the measurement changed the estimate, so that it
  // goes out at once rather than with the next odometry sample (up to 10 ms later). It carries
  // the stamp of the pose already published for the newest odometry: a consumer keeps the
  // newest pose per stamp. Nothing is returned when the estimator holds the measurement for a
  // later odometry sample (ukf_lrf fuses at the measurement's own stamp) or gates it out.
  std::optional<LocalizerOutput> on_range(const std::string& robot_id, const RangeMeasurement& range);
  // Laser scans reach estimators that use them (uses_laser()); others never see one.
  bool uses_laser() const { return uses_laser_; }
  // Whether the estimator finds itself from the beacons (Estimator::localizes_from_beacons), not
  // told where it starts.
  bool localizes_from_beacons() const { return localizes_from_beacons_; }
  std::optional<LocalizerOutput> on_laser(const std::string& robot_id, const LaserScanSample& scan);
  // Each estimator hears the beacons one way (Estimator::beacon_input): decoded ranges, raw times
  // of flight, or pulse arrivals (seed 002); the participant subscribes to that topic alone, and
  // the other kinds never reach the estimator (each pulse reaches it once).
  BeaconInput beacon_input() const { return beacon_input_; }
  std::optional<LocalizerOutput> on_raw_tof(const std::string& robot_id, const RawTofSample& tof);
  std::optional<LocalizerOutput> on_pulse(const std::string& robot_id, const PulseArrivalSample& pulse);
  // Restarts the robot's estimator from a given pose (counted as initial_pose.<reason> if refused).
  void on_initial_pose(const std::string& robot_id, StampNs stamp_ns, const Pose2& pose_map_base,
                       const Cov3& covariance);
  // The robot's estimator's associations of anonymous ranges since last asked (evaluation).
  std::vector<Estimator::Association> take_associations(const std::string& robot_id);
  // The bus says the robot's ranges stopped (the beacon_range reader's deadline, two slots, was
  // missed): its poses are published degraded, coasting on odometry, until a range arrives.
  void on_ranges_silent(const std::string& robot_id);
  // The odometry reader's deadline (five periods, 50 ms) passed without a sample of the robot. After
  // kOdometrySilentAfterMisses in a row the robot's odometry is silent (a gateway that stopped, hung
  // or lost its link): its pose cannot follow the robot, so it is degraded until odometry arrives
  // again. One or two misses are a stall of a busy machine, not a dead input. The robots whose
  // odometry is silent, for the Diagnostics.
  static constexpr int kOdometrySilentAfterMisses = 4;
  void on_odometry_deadline_missed(const std::string& robot_id);
  std::vector<std::string> odometry_silent_robots() const;
  // Late measurements fused at their own stamp, over every robot (core/out_of_sequence_fusion).
  std::uint64_t replays() const;

  const std::string& estimator_name() const { return estimator_name_; }
  bool serves(const std::string& robot_id) const {
    return robot_filter_.empty() || robot_id == robot_filter_;
  }
  const RejectionCounter& counts() const { return counts_; }  // reasons prefixed odometry./range.
  std::size_t robot_count() const { return robots_.size(); }
  // The robot's estimator (for evaluation: an estimator's own state beside its pose); null for a
  // robot not seen.
  const Estimator* estimator(const std::string& robot_id) const {
    const auto it = robots_.find(robot_id);
    return it == robots_.end() ? nullptr : &it->second.fusion.estimator();
  }
  std::vector<std::string> robot_ids() const;  // the robots it has an estimator for, sorted
  // Drops the robot's estimator and what it held (another localizer shard serves it now); its
  // next sample, if it comes back, starts it afresh. Returns whether it was served.
  bool release_robot(const std::string& robot_id) { return robots_.erase(robot_id) != 0; }
  // The worst status over the robots served (kOk when none).
  PoseStatus worst_status() const;
  // The robot's start-up condition while it has no pose (nullopt once it has one, or unknown).
  std::optional<StartupWait> startup_wait(const std::string& robot_id) const;
  // Selective activation (seed 004 Sec. 3): the beacons to fire next for the robot, from its
  // pose and each beacon's reach (core/firing_plan.hpp); nullopt while the robot has no pose
  // that is ok (initializing, degraded or lost: every beacon must fire) or there is no map.
  std::optional<FiringPlan> firing_plan(const std::string& robot_id) const;
  StartupSummary startup_summary() const;

 private:
  struct Robot {
    explicit Robot(std::unique_ptr<Estimator> estimator) : fusion(std::move(estimator)) {}
    OutOfSequenceFusion fusion;
    std::set<std::uint32_t> beacons_used;
    bool ranges_silent = false;
    int odometry_deadlines_missed = 0;  // in a row, since the robot's last odometry sample
    bool odometry_silent() const { return odometry_deadlines_missed >= kOdometrySilentAfterMisses; }
    std::optional<StampNs> jump_candidate_ns;  // an odometry stamp far behind the time line
    std::optional<StampNs> state_sent_ns;      // stamp of the last output that carried the state
    PoseStatus status() const;
  };
  // Two odometry samples in a row more than kClockJumpMinNs behind the time line, and at most
  // kClockJumpConfirmationNs apart: the clock went back.
  static constexpr StampNs kClockJumpMinNs = kNsPerSecond;
  static constexpr StampNs kClockJumpConfirmationNs = 200 * kNsPerMillisecond;
  bool clock_jumped_back(Robot& r, const OdometrySample& odometry);
  // A new estimator for the robot, on the current map: what the old one holds no longer holds
  // (the clock went back, the beacons changed, its estimate became unusable). An estimator that
  // finds its pose from the beacons starts from nothing, initializing until it has a fix: the
  // old pose cannot be trusted (a replayed recording starts where the robot was then, not where
  // it is). One that must be placed (localizes_from_beacons() false) is placed at the old pose,
  // less sure, as no better guess exists. `next`, when given, is the odometry sample the new
  // estimator starts its time line with (a clock jump): its result is returned.
  InputResult restart_robot(Robot& r, const OdometrySample* next = nullptr);
  Robot* robot(const std::string& robot_id, const char* kind);
  // The robot's pose to publish (none before its first fix), with the beacons fused since the last.
  std::optional<LocalizerOutput> output(const std::string& robot_id, Robot& r);
  // A range, scan or raw time of flight: fused at its stamp, counted under its kind
  // ("range.", "laser.", "raw_tof."), the corrected pose returned when it changed.
  std::optional<LocalizerOutput> on_measurement(const std::string& robot_id, EstimatorInput input);
  // A checked calibration's groups into the site's, each refused on its own (see on_calibration);
  // the site's calibration to every robot but `source` when it changed.
  bool merge_into_site(const BeaconCalibration& calibration, const Robot* source);
  void drop_calibration_off_the_map();
  // The site's calibration (it fits the map) to the robot's estimator, if it uses one.
  void give_calibration(Robot& r);
  // What the robot's estimator calibrated since last asked, into the site's calibration (and so
  // to every other robot).
  void take_calibration(Robot& r);
  std::optional<LocalizerOutput> correction_output(const std::string& robot_id, Robot& r,
                                                   const std::optional<PoseEstimate>& before);

  std::string estimator_name_;
  EstimatorConfig config_;
  std::string robot_filter_;
  bool uses_laser_ = false;
  bool localizes_from_beacons_ = true;
  BeaconInput beacon_input_ = BeaconInput::kRanges;
  BeaconMap map_;
  std::map<std::string, Robot> robots_;
  RejectionCounter counts_;
  std::uint64_t beacon_map_changes_ = 0;
  bool uses_calibration_ = false;
  BeaconCalibration calibration_;  // checked, groups sorted by id
  std::uint64_t calibration_revision_ = 0;
};

}  // namespace beaconloc
