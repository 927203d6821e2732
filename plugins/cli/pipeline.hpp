#pragma once
// Running the whole pipeline (gateway, decoder, localizer) on a source and scoring it: in one
// process (demo, run) or one process per participant (run --processes).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "beaconloc/dds/participant.hpp"
#include "bridge_participant.hpp"
#include "evaluation.hpp"
#include "gateway_participant.hpp"
#include "pose_bound.hpp"
#include "replay/replay_source.hpp"
#include "sim/scenario.hpp"
#include "tof_decoder.hpp"

namespace beaconloc::cli {

// Where the gateway's data comes from: the built-in scenario, a scenario file or a recording.
struct SourceChoice {
  std::string scenario_file;  // empty: built-in default (unless replay_dir)
  std::string replay_dir;
  ReplayOptions replay;
  std::vector<std::string> faults;  // sim/faults.hpp forms; simulated sources only
};

struct LoadedSource {
  SourceChoice choice;
  std::uint64_t seed = 1;
  std::unique_ptr<Source> source;
  std::optional<sim::Scenario> scenario;  // when simulated
  std::string label;                      // for titles and metrics.json
};

// Throws a std::runtime_error naming the file when it cannot be loaded. The seed and duration
// default to the scenario's when not given (nullopt).
LoadedSource load_source(const SourceChoice& choice, std::optional<std::uint64_t> seed);

struct LocalizerSettings {
  std::string estimator = "range_ekf";
  // Estimator plugins built out of tree (files, or directories of them), loaded before the estimator
  // is made (localizer/estimator_plugins.hpp).
  std::vector<std::string> estimator_plugins;
  std::string robot;                    // empty: every robot
  std::vector<std::string> parameters;  // NAME=VALUE
  // Receivers in the robot frame, "x:y,x:y,...": empty for a circle of receiver_count at
  // receiver_radius_m (the localizer alone) or the source's own receivers (demo, run).
  std::string receivers;
  double receiver_radius_m = 0.19;
  int receiver_count = 3;
  double receiver_height_m = 0.0;
  std::string map_file;              // ROS map_server YAML; empty: none (or the scenario's, in run)
  std::vector<double> initial_pose;  // x, y, yaw; empty: none (or the scenario's start, in run)
  std::string calibration_file;      // the site's beacon calibration kept here; empty: on the bus only
  std::string firing_schedule = "all";  // "selective": send the gateways firing plans (seed 004)

  // Throws std::invalid_argument naming the bad option. fallback: receivers when none given.
  EstimatorConfig config(const std::optional<ReceiverArray>& fallback = std::nullopt) const;
  bool selective_activation() const { return firing_schedule == "selective"; }
  // The arguments that give the same settings to `beaconloc localizer`.
  std::vector<std::string> arguments(const std::optional<ReceiverArray>& fallback = std::nullopt) const;
};

struct PipelineOptions {
  dds::DdsOptions dds;
  std::optional<bridge::BridgeOptions> bridge;  // the ROS 2 bridge in the same process (demo)
  GatewayOptions gateway;
  TofDecoderConfig decoder;
  LocalizerSettings localizer;
  std::string out_dir;          // outputs written here when not empty
  bool processes = false;       // one process per participant
  bool print_poses = false;     // a pose line each second (demo)
  bool print_progress = false;  // a progress line every 2 s (run)
};

struct PipelineResult {
  std::size_t poses = 0;
  double pose_rate_hz = 0.0;
  Metrics metrics;
  std::size_t truth_samples = 0;  // 0: the source has no ground truth (a replay without gt.csv)
  std::string diagnostics;        // each participant's counts, one line each
  std::size_t estimator_state_rows = 0;  // written to estimator_state.csv (estimators with such state)
  std::string newest_state;              // each value of that state at its newest stamp, with its sigma
  std::optional<PoseBoundResult> bound;  // simulated sources: the posterior Cramer-Rao bound (docs/bound.md)
};

// Runs to the end of the source (or the duration), then evaluates. With out_dir, writes
// truth.csv, estimate.csv, beacons.csv, metrics.json, trajectory.svg and error.svg there, and
// estimator_state.csv when the estimator published state beside its poses (EstimatorState).
PipelineResult run_pipeline(const PipelineOptions& options, LoadedSource source, const std::string& self_exe);

// `beaconloc eval`: metrics.json, trajectory.svg and error.svg from a truth and an estimate CSV.
Metrics evaluate_files(const std::string& truth_csv, const std::string& estimate_csv,
                       const std::string& out_dir, const std::string& beacons_csv, double max_truth_gap_s);

std::string format_metrics(const Metrics& m);

}  // namespace beaconloc::cli
