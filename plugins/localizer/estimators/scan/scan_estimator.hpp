#pragma once
// scan: seed 003 (Gualda et al., "Simultaneous Calibration and Navigation (SCAN) of Multiple
// Ultrasonic Local Positioning Systems"), Fig. 3 and 4. The robot's pose in the map comes from
// the global filter (eq. 1), updated by the globally referenced groups (GRULPSs) and by every
// locally referenced group (LRULPS) once that group is calibrated. While the robot is inside an
// uncalibrated LRULPS n, a filter of its own tracks the robot in n's frame (eq. 2); where the robot
// hears both n and a group the global filter already uses, each epoch gives a pair of positions
// (n's frame, map), from which the transform of n to the map is found (Sec. 3.5: the analytic
// method averaged over the overlap, or the numerical one over spread points), and n's beacons'
// map positions from it (eq. 42-43). From then on n is used as a GRULPS (Fig. 3).
//
// Each frame's filter (frame_filter.hpp) is the EKF, the UKF or the H-infinity filter, on
// ranges (spherical) or range differences (hyperbolic); each frame starts from two Gauss-Newton
// fixes of its group (group_fix.hpp, frame_start.hpp).
//
// Deviations and choices (the paper is silent):
//  - the overlap ends when the global filter has had no correction for overlap_end_s (the robot
//    has left the known groups' coverage; the group's own filter is not asked): the calibration
//    is then final (Sec. 3.5.1: "when the MR is in the last position of the common coverage
//    area"). A group calibrated once stays so.
//  - a calibrated beacon's covariance is the global track's position covariance averaged over
//    the pairs plus the transform's misfit (eq. 46's mean error, half of its square per axis);
//    the global filter adds it to the range's variance along the line of sight.
//  - the paper's groups emit at once; here a group's beacons fire in turn (80 ms for four), and a
//    fix from ranges taken along 3 cm of travel is biased across the track at a group's edge
//    (10 cm on seed 003: the ranges to the beacons that fire later are shorter). A fix is made of
//    the ranges brought to the epoch's last instant by each beacon's range rate since its
//    previous range (one group cycle before); a range without a recent predecessor waits. A
//    range that changed by more than the receiver moved since (odometry) has no rate: an echo is
//    in one of the two, and an echo is the longer; a range longer than that is not the next
//    one's predecessor either. A range shorter than that shows its predecessor was an echo the
//    check could not see: its rate is taken from the range before. A spherical epoch with a
//    range to spare whose fix fails is fixed without the one range that is an echo
//    (solve_group_fix_without_an_echo), counted (echoes_left_out_of_fixes).
//  - a vector of the analytic average whose scale is off 1 by more than 10 % is left out of it
//    (similarity_transform.hpp: the frames are in metres; one wrong pair spoils the mean).
//  - the inverse trajectory (Sec. 3.6, inverse_trajectory.hpp): the inputs since the robot last
//    left a GRULPS are kept; once it has been back in a GRULPS's coverage (any, the same one
//    after a loop too) for inverse_after_s, with groups calibrated on the way, the drive is run
//    backwards from there on a fresh estimator, and each group takes the calibration, forwards
//    or backwards, whose beacon covariance is the smaller (the paper takes the backwards one for
//    "the last LRULPS calibrated"; the covariance says which is last from either end).
#include <deque>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "beaconloc/core/beacon_calibration.hpp"
#include "beaconloc/core/estimator_base.hpp"
#include "scan/calibration_covariance.hpp"
#include "scan/frame_filter.hpp"
#include "scan/frame_start.hpp"
#include "scan/group_fix.hpp"
#include "scan/input_log.hpp"
#include "scan/inverse_trajectory.hpp"
#include "scan/similarity_transform.hpp"

namespace beaconloc::scan {

enum class TransformMethod : std::uint8_t { kAnalytic, kNumerical };

struct ScanParameters {
  FrameFilterSettings filter;
  Geometry geometry = Geometry::kSpherical;
  TransformMethod transform = TransformMethod::kAnalytic;
  double d_min_m = 2.5;             // Sec. 4.1: "we have set this value to 2.5 m"
  int numerical_points = 20;        // Sec. 3.5.2: "a configurable parameter" (value not given)
  FrameStartSettings start;
  // A group's epoch: its ranges within this of the first (its beacons fire in turn within 80 ms
  // in seed003_scan.yaml; at once in the paper).
  double epoch_window_s = 0.1;
  double overlap_end_s = 2.0;       // see the header: > 2 of a group's cycles (0.76 s)
  double max_odometry_gap_s = kDefaultMaxOdometryGapS;
  double wheel_velocity_variance_floor_m2ps2 = 1e-6;
  bool inverse_trajectory = true;  // Sec. 3.6
  // In a GRULPS's coverage this long before the backwards drive starts from there: the drive
  // needs the GRULPS's fixes at its start (5 s, on seed 003 at the coverage's edge, was too
  // short on one seed in four: the backwards global frame started as it left the GRULPS).
  double inverse_after_s = 10.0;
  // The inputs kept for it (8.6 MB; 18 min of seed 003's drive, 100 Hz odometry and 12 ranges a
  // second); a longer leg between two GRULPSs has no backwards drive (inverse_passes_skipped
  // counts it). The drive runs inside the odometry step that starts it: 2.4 ms (EKF) for seed
  // 003's 11 000 inputs, about 26 ms at the cap (BENCHMARKS.md).
  std::size_t max_recorded_inputs = 120000;

  static ScanParameters from(const EstimatorConfig& config);
};

class ScanEstimator final : public EstimatorBase {
 public:
  explicit ScanEstimator(const EstimatorConfig& config);
  std::string name() const override { return "scan"; }
  void set_beacon_map(const BeaconMap& map) override;
  InputResult predict(const OdometrySample& odometry) override;
  InputResult update(const RangeMeasurement& range) override;
  std::unique_ptr<Estimator> clone() const override { return std::make_unique<ScanEstimator>(*this); }
  std::vector<StateValue> state_values() const override;
  // The drive is over (the end of a recording, the virtual drive of Sec. 3.6): every open epoch
  // is taken, every overlap under way ends (its group calibrated, if it can be), and a backwards
  // drive that was waiting for inverse_after_s runs now.
  void finish();

  // The groups calibrated so far (each once its overlap ended), in the order they were.
  const BeaconCalibration& calibration() const { return calibration_; }
  // Calibrations found before (by another robot, or by this one before a restart: what the
  // BeaconCalibration topic and the calibration file will carry): each group in it is used at
  // once as calibrated, its beacons at their calibrated map positions, with no calibration drive.
  // Refused whole (false) when check_calibration refuses it or it does not fit the map: a group
  // the map does not hold as locally referenced, or a group's beacons not exactly the map's.
  // Given after the map (a new map drops it with everything else).
  // A group held with that very calibration already is left as it is.
  bool uses_calibration() const override { return true; }
  bool use_calibration(const BeaconCalibration& calibration) override;
  std::optional<BeaconCalibration> take_calibration_update() override;
  // Groups whose overlap is under way: the transform so far (nullopt before one exists).
  std::optional<GroupCalibration> provisional_calibration(std::uint32_t group) const;

 private:
  ScanEstimator(const EstimatorConfig& config, const ScanParameters& params);
  PoseBelief pose_belief() const override { return {global_.filter.pose(), global_covariance()}; }
  // The global filter's covariance, and, while no GRULPS has corrected it within overlap_end_s,
  // the covariance of the calibrated beacon that last did: a group's beacons share one error
  // (their transform's), which the filter, taking each range's as its own, cannot hold, however
  // many ranges it fuses (a consider covariance: the pose is as uncertain as the beacons are).
  Cov3 global_covariance() const;
  // The largest covariance of a calibrated group's beacons (the group of beacon_id): what the
  // global frame is as unsure of after they corrected it. Zero for a beacon not calibrated.
  Eigen::Matrix2d calibrated_group_covariance(std::uint32_t beacon_id) const;
  StartupWait waiting_for() const override { return waiting_for_; }

  // A beacon where a frame's filter may use it: its position in that frame and the extra
  // covariance of that position (calibrated beacons only).
  struct FrameBeacon {
    Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
    Eigen::Matrix2d covariance_m2 = Eigen::Matrix2d::Zero();
  };
  struct EpochEntry {
    std::uint32_t beacon_id = 0;
    double range_m = 0.0;
    double variance_m2 = 0.0;
    Pose2 odometry_pose = Pose2::Zero();
    StampNs stamp_ns = 0;
    std::optional<double> range_rate_mps;  // from this beacon's previous range, when recent
  };
  struct Epoch {
    std::uint32_t group = 0;
    std::vector<EpochEntry> ranges;
  };
  // One frame: its filter, how it starts, and when it was last corrected.
  struct Frame {
    explicit Frame(const ScanParameters& p) : filter(p.filter), start(p.start) {}
    FrameFilter filter;
    FrameStart start;
    bool started = false;
    // The global frame only: GRULPS fixes contradict the filter (it drifted between groups whose
    // calibration was off, beyond what its covariance says): the frame is found again from two
    // GRULPS fixes, as at the start, while the filter goes on, degraded; fixes that agree with
    // the filter again end it.
    bool relocating = false;
    int fixes_in_a_row = 0;  // GRULPS fixes: > 0 that many disagreeing in a row, < 0 agreeing
    bool unconfirmed = false;  // corrected after a coast, and no fix has agreed since
    std::optional<StampNs> last_correction_ns;
  };
  // An LRULPS while it is calibrated: its frame and the overlap's pairs.
  struct LocalGroup {
    explicit LocalGroup(const ScanParameters& p) : frame(p), average(p.d_min_m) {}
    Frame frame;
    AnalyticAverage average;
    std::vector<PointPair> track;       // every pair of the overlap, oldest first (numerical)
    CalibrationCovariance covariance;  // of the beacons' map positions, from the pairs
    std::size_t pairs = 0;
  };

  void close_epochs(StampNs now_ns, bool all);
  void process_epoch(const Epoch& epoch);
  // The epoch's Gauss-Newton fix in the frame (Sec. 3.2-3.3), nullopt when it gives none (too
  // few ranges, the solver's refusal: what the global frame waits for, before its first pose).
  std::optional<GroupFix> fix_of(const Epoch& epoch, bool global);
  // The epoch's fix given to the frame's start (a fix that started the frame included).
  std::optional<GroupFix> start_frame(Frame& frame, const Epoch& epoch, bool global);
  // An epoch of a known group while the global frame tracks: its fix checked against the filter
  // (agreeing, it confirms the pose; a GRULPS's disagreeing ones relocate the frame).
  void check_fix(const Epoch& epoch, bool grulps);
  void global_corrected(StampNs now_ns);
  bool suspect() const override {
    return global_.relocating || global_.unconfirmed || global_.fixes_in_a_row > 0;
  }
  bool fuse_epoch(Frame& frame, const Epoch& epoch, bool global);
  // global_pose: the global frame's pose at the instant the local point is of.
  void add_pair(LocalGroup& local, const Eigen::Vector2d& local_receiver_m, const Pose2& global_pose);
  void finish_overlaps(StampNs now_ns);
  std::optional<GroupCalibration> transform_of(std::uint32_t group, const LocalGroup& local, StampNs now_ns) const;
  // Where a beacon is for the global filter (a map beacon, or a calibrated one); nullopt for an
  // uncalibrated one.
  std::optional<FrameBeacon> global_beacon(std::uint32_t id) const;
  bool recently(const std::optional<StampNs>& stamp_ns, StampNs now_ns) const;
  // The global frame may give the twin of a local point: tracking, not relocating, corrected lately.
  bool pairs_possible(StampNs now_ns) const;
  // A correction of the global frame by a group of the map's own (a GRULPS).
  void note_grulps_correction(StampNs now_ns);
  void maybe_run_inverse_trajectory(StampNs now_ns, bool now_or_never);
  void calibrate(std::uint32_t group, const GroupCalibration& g);
  void record(const RecordedInput& input);

  EstimatorConfig config_;  // for the backwards drive's estimator
  ReceiverArray receivers_;
  ScanParameters params_;
  StartupWait waiting_for_;
  Pose2 odometry_pose_ = Pose2::Zero();
  StampNs odometry_integrated_ns_ = 0;  // the time the odometry integrated so far (gaps not)
  Frame global_;
  std::map<std::uint32_t, LocalGroup> local_;           // by group, the LRULPSs not calibrated yet
  std::map<std::uint32_t, CalibratedBeacon> calibrated_;  // by beacon id
  BeaconCalibration calibration_;
  bool calibration_changed_ = false;  // since take_calibration_update last asked
  std::map<std::uint32_t, Epoch> open_epochs_;  // by group
  struct RangeSample {  // a range as the next one's predecessor
    StampNs stamp_ns = 0;
    double range_m = 0.0;
    double variance_m2 = 0.0;
    Pose2 odometry_pose = Pose2::Zero();  // the dead-reckoned pose when it came
    StampNs integrated_ns = 0;            // odometry_integrated_ns_ then
  };
  // A beacon's previous ranges, for its range rate: not those longer than the receiver moved
  // (echoes), though an echo that check could not see may be latest.
  struct LastRange {
    StampNs newest_ns = 0;  // the stamp of its newest range, echo or not (a duplicate is refused)
    RangeSample latest;
    // The one before latest, for the range after an echo that was not caught (latest, when the
    // next range is shorter than the receiver's motion allows).
    std::optional<RangeSample> before;
  };
  // How a range compares with a predecessor: within what the receiver moved since (rate_mps), or
  // longer or shorter than that allows.
  enum class RangeChange : std::uint8_t { kTooOld, kWithinMotion, kLonger, kShorter };
  struct Compared {
    RangeChange change = RangeChange::kTooOld;
    double rate_mps = 0.0;
  };
  Compared compare(const RangeMeasurement& r, const RangeSample& predecessor) const;
  void echo_left_out_of_fix(const EpochEntry& echo);
  std::map<std::uint32_t, LastRange> last_range_;  // by beacon
  // Sec. 3.6: the inputs since the robot last left a GRULPS, and when it came back to one.
  InputLog<RecordedInput> log_;
  bool log_full_ = false;
  std::optional<StampNs> last_grulps_correction_ns_;
  // The largest covariance of the calibrated group whose beacons last corrected the global
  // frame (calibrated_group_covariance): global_covariance().
  Eigen::Matrix2d calibrated_correction_m2_ = Eigen::Matrix2d::Zero();
  std::optional<StampNs> back_in_grulps_since_ns_;
  std::size_t calibrated_since_grulps_ = 0;
  std::size_t inverse_passes_ = 0;
  std::size_t inverse_passes_skipped_ = 0;
  std::size_t echoes_left_out_of_fixes_ = 0;  // solve_group_fix_without_an_echo
  std::optional<std::pair<std::uint32_t, StampNs>> last_echo_left_out_;  // its beacon and stamp
};

}  // namespace beaconloc::scan
