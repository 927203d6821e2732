#pragma once
// The estimator plugin API. An estimator is pure maths: it is pushed inputs (push: odometry to
// predict, ranges, scans and raw times of flight to update) and asked for its estimate. It never reads a clock and never includes a
// DDS header, so the same code runs live, in replay and in tests.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/beacon_calibration.hpp"
#include "beaconloc/core/beacon_map.hpp"
#include "beaconloc/core/estimator_input.hpp"
#include "beaconloc/core/measurements.hpp"
#include "beaconloc/core/occupancy_grid.hpp"
#include "beaconloc/core/pose2.hpp"
#include "beaconloc/core/receiver_array.hpp"
#include "beaconloc/core/rejection.hpp"

namespace beaconloc {

enum class PoseStatus { kInitializing, kOk, kDegraded, kLost };
const char* to_string(PoseStatus s);

struct PoseEstimate {
  StampNs stamp_ns = 0;
  Pose2 pose_map_base = Pose2::Zero();
  Cov3 covariance = Cov3::Identity();
  PoseStatus status = PoseStatus::kInitializing;
};

// Whether an estimate may go out: finite pose, and a symmetric covariance of finite,
// non-negative variances; a position within kMaxMapCoordinateM, a heading within kMaxAngleRad and
// no variance beyond kMaxMapCoordinateM^2 (core/limits.hpp: a pose beyond any site says nothing,
// and its squared error would overflow a metric to inf). Every output path (localizer, bridge,
// monitor, files) holds to it.
bool publishable(const PoseEstimate& estimate);

// The answer to one pushed input: accepted, or rejected with a reason (counted in Diagnostics
// under its stable name, core/rejection.hpp).
struct InputResult {
  bool accepted = true;
  std::optional<Rejection> rejection;  // set exactly when not accepted
  static InputResult ok() { return {}; }
  static InputResult rejected(Rejection reason) { return {false, reason}; }
  // What a filter's update or prediction did: accepted when applied, else its rejection.
  static InputResult of(FilterOutcome outcome) {
    const std::optional<Rejection> reason = rejection_for(outcome);
    return reason ? rejected(*reason) : ok();
  }
};

struct EstimatorConfig {
  ReceiverArray receivers;
  // Estimator-specific, read and checked by each plugin (core/estimator_parameters.hpp).
  std::map<std::string, double> parameters;
  // The occupancy grid of the map, for estimators with a laser model; null when none was given.
  std::shared_ptr<const OccupancyGrid> occupancy_grid;
  // Where the robot starts, for estimators placed by hand (seed 001 Sec. 4.1); others ignore it.
  std::optional<Pose2> initial_pose;
};

// NAME=VALUE items (the --param options) as estimator parameters. Throws std::invalid_argument
// naming the option and the item that is not NAME=VALUE, whose value is not a decimal number
// (core/decimal.hpp: "0x1p1", "inf", "1e400" are refused), or whose name an earlier item gave
// already. Whether the estimator knows the name and the value is in its range is the
// estimator's check (core/estimator_parameters.hpp).
std::map<std::string, double> parse_estimator_parameters(const std::vector<std::string>& items,
                                                         const std::string& option_name);

// Why an estimator has no pose yet: the start-up condition it waits for. Stable snake_case names
// (to_string), counted per robot in the localizer's Diagnostics.
enum class StartupCondition {
  kNoBeaconMap,           // no beacon map yet
  kNoOdometry,            // no odometry sample yet (a pose is stamped by the odometry)
  kNeedsInitialPose,      // placed by hand: --initial-pose or an initial_pose message
  kTooFewBeacons,         // value of limit beacons heard
  kTooFewRanges,          // value of limit usable ranges (after the echo screen)
  kFixFailed,             // the global fix found no pose (note: the solver's reason)
  kMirrorAmbiguous,       // beacons on one line: the mirror image fits as well (value: its chi-square margin)
  kPositionTooUncertain,  // the fix's position sigma (value, m) above the limit
  kHeadingTooUncertain,   // the fix's heading sigma (value, rad) above the limit
  kNoDoubleBurst,         // pulses without ids: none heard yet from the beacon that marks the cycle
  kNeedsMotion,           // the heading comes from two fixes: value m moved since the first of limit
};
const char* to_string(StartupCondition c);

struct StartupWait {
  StartupCondition condition = StartupCondition::kNoBeaconMap;
  double value = 0.0;  // the number that matters (see StartupCondition), and the limit it must reach
  double limit = 0.0;
  std::string note;  // for people only (e.g. the solver's failure); never decided on
  // "2 of 3 beacons heard", "fix too uncertain: position sigma 0.52 m > 0.30 m", ...
  std::string describe() const;
};

// How an estimator hears the beacons.
enum class BeaconInput {
  kRanges,         // the decoder's ranges (BeaconRange): the beacon's firing time is known (radio)
  kRawTof,         // raw times of flight (RawTof): the firing time known, the range its own to work out
  kPulseArrivals,  // pulse arrivals only (PulseArrival): no firing time, no id (seed 002)
};
// Whether `input` is a beacon measurement of that kind (false for odometry and laser scans).
bool is_beacon_input(const EstimatorInput& input, BeaconInput kind);

class Estimator {
 public:
  virtual ~Estimator() = default;
  virtual std::string name() const = 0;
  // Given once, before the first sample (or when the first map arrives after some): a map that
  // changes later gets a new estimator (LocalizerCore::restart_robot), since what an estimator
  // holds was measured against the beacons it had.
  virtual void set_beacon_map(const BeaconMap& map) = 0;
  // Whether it finds its pose from the beacons alone; false for one that must be placed
  // (given an initial pose): a restart then places it where it was.
  virtual bool localizes_from_beacons() const { return true; }
  // The one dispatch on an input's kind (core/estimator_input.hpp): to predict, update,
  // update_laser or update_raw_tof.
  InputResult push(const EstimatorInput& input);
  virtual InputResult predict(const OdometrySample& odometry) = 0;
  virtual InputResult update(const RangeMeasurement& range) = 0;
  // Laser scans, for the estimators that use them (uses_laser()); the others are never pushed one.
  virtual bool uses_laser() const { return false; }
  virtual InputResult update_laser(const LaserScanSample& /*scan*/) {
    return InputResult::rejected(Rejection::kLaserUnused);
  }
  // What the estimator hears the beacons as (BeaconInput): the localizer subscribes to that topic
  // alone, and the estimator is never pushed the other kinds.
  virtual BeaconInput beacon_input() const { return BeaconInput::kRanges; }
  // Raw times of flight, for the estimators that turn them into ranges themselves.
  virtual InputResult update_raw_tof(const RawTofSample& /*tof*/) {
    return InputResult::rejected(Rejection::kRawTofUnused);
  }
  // Pulse arrivals with no firing time, for the estimators that track the beacons' cycle (seed 002).
  virtual InputResult update_pulse(const PulseArrivalSample& /*pulse*/) {
    return InputResult::rejected(Rejection::kPulseUnused);
  }
  // Anonymous ranges the estimator associated with a beacon since last asked (for evaluation
  // against the simulator's truth); empty for estimators that need identified ranges.
  struct Association {
    StampNs range_stamp_ns;
    std::uint32_t receiver_id;
    std::uint32_t beacon_id;
  };
  virtual std::vector<Association> take_associations() { return {}; }
  // Measurements held for a later step whose fusion then failed (the step itself succeeded),
  // as rejection reasons since last asked: the localizer counts them.
  virtual std::vector<Rejection> take_deferred_rejections() { return {}; }
  // What the site learns from a robot (seed 003: locally referenced beacon groups calibrated
  // while it drives), shared with every robot: the estimator's whole calibration when it changed
  // since last asked; nullopt otherwise, and always for estimators that calibrate nothing.
  virtual std::optional<BeaconCalibration> take_calibration_update() { return std::nullopt; }
  // A calibration found before (another robot, a restart: the BeaconCalibration topic, a file),
  // given after the map: its groups are used at once, with no calibration drive. False when the
  // estimator refuses it (it does not fit the map) or uses no calibration.
  virtual bool uses_calibration() const { return false; }
  virtual bool use_calibration(const BeaconCalibration& /*calibration*/) { return false; }
  // Restart from this pose (an operator's or rviz2's initial pose), stamped stamp_ns; the
  // estimators that cannot be placed refuse with a reason.
  virtual InputResult reset(StampNs /*stamp_ns*/, const Pose2& /*pose_map_base*/,
                            const Cov3& /*covariance*/) {
    return InputResult::rejected(Rejection::kResetUnsupported);
  }
  // The current pose; nullopt until the estimator has one.
  virtual std::optional<PoseEstimate> estimate() const = 0;
  // What it estimates beside the pose, named with their units (seed 002: the speed of sound, the
  // beacons' cycle), each with its standard deviation, while it has a pose; empty for most. The
  // localizer publishes them once a second of data time (EstimatorState), for plots and tuning.
  struct StateValue {
    std::string name;  // snake_case with its unit: "speed_of_sound_mps"
    double value = 0.0;
    double sigma = 0.0;
  };
  virtual std::vector<StateValue> state_values() const { return {}; }
  // Status from data time alone (the stamps pushed so far).
  virtual PoseStatus status() const = 0;
  // While estimate() is nullopt, the start-up condition the estimator waits for; nullopt once
  // it has a pose.
  virtual std::optional<StartupWait> startup_wait() const = 0;
  // A copy of the whole state, to roll back to when a measurement arrives late
  // (core/out_of_sequence_fusion.hpp).
  virtual std::unique_ptr<Estimator> clone() const = 0;
};

// The checks of a range's numbers, whichever estimator takes it: finite (non_finite_range),
// positive (invalid_range), within kMaxRangeM (implausible_range), a stamp >= 0 (invalid_stamp).
InputResult check_range_numbers(const RangeMeasurement& range);

// The checks every estimator of identified ranges makes of a range: its numbers, then from an
// identified beacon of the map, to a receiver the robot has. Accepted, or the typed rejection.
InputResult check_range(const RangeMeasurement& range, const BeaconMap& map, std::size_t receiver_count);

// The checks of a pose to reset an estimator from: finite, and a symmetric positive-definite
// covariance (kInvalidInitialPose), within the bounds of a site (kImplausibleInitialPose).
InputResult check_initial_pose(const Pose2& pose_map_base, const Cov3& covariance);

// Status policy shared by estimators: how long without a fused range the pose stays OK.
struct StalenessPolicy {
  StampNs degraded_after_ns = 1'000'000'000;  // 5 missed beacon slots
  StampNs lost_after_ns = 10'000'000'000;
  PoseStatus classify(StampNs now_ns, StampNs last_correction_ns) const {
    const StampNs age = now_ns - last_correction_ns;
    if (age > lost_after_ns) return PoseStatus::kLost;
    if (age > degraded_after_ns) return PoseStatus::kDegraded;
    return PoseStatus::kOk;
  }
};

}  // namespace beaconloc
