#pragma once
// A scenario run without DDS: the simulated source fed straight into the decoder and localizer
// cores (the same code the participants run), every pose scored against the simulator's truth.
// For accuracy tables over many seeds: deterministic, and as fast as the estimator.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "evaluation.hpp"
#include "localizer_core.hpp"
#include "pose_bound.hpp"
#include "sim/scenario.hpp"
#include "source.hpp"
#include "tof_decoder.hpp"

namespace beaconloc {

// What the localizer is told of a scenario, as `beaconloc run --scenario` tells it: its
// receivers, occupancy grid and start pose (or initial_pose).
EstimatorConfig estimator_config_for(const sim::Scenario& scenario, const std::map<std::string, double>& parameters,
                                     const std::optional<Pose2>& initial_pose = std::nullopt);

// The decoder `beaconloc run --scenario` gives the scenario: its range limits and noise, its
// beacon map as the gateway publishes it (locally referenced groups in their own frames).
TofDecoderConfig decoder_config_for(const sim::Scenario& scenario);
TofDecoder scenario_decoder(const sim::Scenario& scenario);

// Every event of a scenario up to duration_s, in stamp order.
std::vector<SourceEvent> simulate(const sim::Scenario& scenario, std::uint64_t seed, double duration_s);

// What the localizer is given for a source event, as the participants deliver it: odometry and
// scans as they are; for an estimator of ranges a TOF decoded into a range by `decoder` (nullopt
// when the decoder refuses it), for one of raw times of flight the TOF itself, for one of pulse
// arrivals the pulse (beacon_input); nullopt for a truth event and for a beacon measurement the
// estimator does not take (the participant does not subscribe to it).
std::optional<EstimatorInput> estimator_input(const std::string& robot_id, const SourceEvent& e,
                                              TofDecoder& decoder, BeaconInput beacon_input);

// Anonymous ranges associated with a beacon by the estimator, scored against the simulator's
// truth (who fired), per true beacon.
struct AssociationTally {
  struct Count {
    std::size_t total = 0;
    std::size_t correct = 0;
  };
  std::map<std::uint32_t, Count> by_beacon;
  std::size_t total() const;
  std::size_t correct() const;
};

// Decoder and localizer cores wired as the participants wire them, knowing the scenario's map,
// receivers, occupancy grid, start pose and range limits.
struct OfflineStack {
  // initial_pose: where an estimator placed by hand is placed; the scenario's start by default.
  explicit OfflineStack(const sim::Scenario& scenario, const std::string& estimator = "range_ekf",
                        const std::map<std::string, double>& parameters = {},
                        std::optional<Pose2> initial_pose = std::nullopt);
  // One simulated event in; the pose the localizer would publish, on odometry events.
  std::optional<LocalizerOutput> feed(const std::string& robot_id, const SourceEvent& e);

  LocalizerCore localizer;
  TofDecoder decoder;
  AssociationTally associations;

 private:
  std::map<StampNs, std::uint32_t> range_truth_;  // range stamp -> the beacon that fired
};

struct OfflineRunResult {
  Metrics metrics;
  std::size_t poses = 0;
  AssociationTally associations;
  RejectionCounter rejections;  // decoder.<reason> and localizer.<reason>
  std::uint64_t replays = 0;    // late measurements fused at their stamp by rolling back
  PoseBoundResult bound;  // the posterior Cramer-Rao bound over the stamps scored (pose_bound.hpp)
  std::vector<Estimator::StateValue> last_state;  // the estimator's state as last published
  // The position error and status of the last pose that has truth at its stamp (nullopt: none).
  std::optional<double> last_position_error_m;
  PoseStatus last_status = PoseStatus::kInitializing;
};

// How the measurements reach the localizer: in stamp order, or each TOF and scan late by a
// uniform random delay in [0, max_measurement_delay_ns] (odometry on time), as a decoder hop and a
// busy bus deliver them.
struct Delivery {
  StampNs max_measurement_delay_ns = 0;
};

// The simulated events in the order they arrive under the delivery (stable: ties keep stamp
// order). The delays are drawn from their own generator seeded by seed.
std::vector<SourceEvent> deliver(std::vector<SourceEvent> events, const Delivery& delivery,
                                 std::uint64_t seed);

// Scores poses from settle_s after the first one (the first global fix is not tracking).
// parameters: NAME=VALUE items; std::invalid_argument names a bad one.
OfflineRunResult run_scenario_offline(const sim::Scenario& scenario, std::uint64_t seed,
                                      const std::string& estimator,
                                      const std::vector<std::string>& parameters, double settle_s = 0.0,
                                      const Delivery& delivery = {});

// Seed 004 Sec. 3-4: a run whose beacons fire either all in turn (the scenario's firing order)
// or selectively, the beacons the localizer plans for the robot (LocalizerCore::firing_plan)
// before each slot, as the gateway honours the firing-plan topic. Every pose the localizer gives
// on odometry, against the truth.
enum class FiringSchedule { kAll, kSelective };
struct TrackedPose {
  double t_s = 0.0;
  Eigen::Vector2d position_error_map_m = Eigen::Vector2d::Zero();  // estimate - truth, along x and y
  double position_error_m = 0.0;
  double heading_error_rad = 0.0;  // wrapped
  double position_nees = 0.0;      // e^T P^-1 e over (x, y): 2 on average for an honest covariance
  PoseStatus status = PoseStatus::kInitializing;
};
struct FiringScheduleRun {
  std::vector<TrackedPose> poses;
  std::uint64_t slots_fired = 0;  // slots in which a beacon fired
  std::uint64_t slots_heard = 0;  // of those, slots some receiver heard
  std::uint64_t tofs = 0;         // times of flight heard (a receiver's pulse from a firing)
  RejectionCounter rejections;    // localizer.<reason>
  // The first time from which every later pose is within position_m and heading_rad of the
  // truth; nullopt when the run never settles so.
  std::optional<double> converged_s(double position_m, double heading_rad) const;
};
FiringScheduleRun run_firing_schedule(const sim::Scenario& scenario, std::uint64_t seed, const std::string& estimator,
                                      const std::map<std::string, double>& parameters, FiringSchedule schedule,
                                      std::optional<Pose2> initial_pose = std::nullopt);

struct AccuracyRow {
  std::string scenario;
  std::string estimator;
  std::vector<Metrics> runs;                        // one per seed
  std::vector<AssociationTally> associations;       // one per seed, where the ranges are anonymous
  std::map<std::string, std::uint64_t> rejections;  // summed over the seeds
  std::vector<PoseBoundRms> bounds;                 // one per seed scored, where the bound follows the scenario
  std::string bound_unavailable;                    // why not, when it does not
  bool laser_fused = false;
};

// A markdown table: mean and standard deviation over the seeds of E_p RMS, E_phi RMS, E_S mean
// and the NEES-in-band fraction, one row per scenario and estimator.
std::string accuracy_table_markdown(const std::vector<AccuracyRow>& rows);

// The estimators beside the posterior Cramer-Rao bound (pose_bound.hpp): E_p RMS and E_phi RMS
// as quadratic means over the seeds, the bound's the same way, and their ratios (1: at the bound;
// each ratio is ours over the bound, both over the same seeds and stamps).
std::string bound_table_markdown(const std::vector<AccuracyRow>& rows);

// Seed 001 Tables 4-7: mean, standard deviation, RMS and maximum of the distance error, and the
// rate of correct association per beacon and overall, each as mean +- spread over the seeds.
std::string distance_table_markdown(const std::vector<AccuracyRow>& rows);

// Seed 002 Sec. 4: the path error's standard deviation and maximum (Metrics::path_error_*), mean
// +- spread over the seeds and the largest of any seed, beside E_p, E_phi and NEES in band.
std::string path_table_markdown(const std::vector<AccuracyRow>& rows);

}  // namespace beaconloc
