// beaconloc: one executable, one subcommand per participant (gateway, decoder, localizer), the
// whole pipeline on a source (demo, run), scoring of recorded tracks (eval), and a monitor.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "bridge_participant.hpp"
#include "decoder_participant.hpp"
#include "localizer_participant.hpp"
#include "monitor.hpp"
#include "number_options.hpp"
#include "offline_run.hpp"
#include "pipeline.hpp"
#include "sim/faults.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc::cli {
namespace {

using namespace std::chrono_literals;

// The ranges of the numeric options (number_options.hpp validates every one): the physical
// limits of core/limits.hpp where the option is one of those quantities.
constexpr bool kOpen = true;         // (min, max]: the option must be > min
constexpr double kMaxAgeMs = 6e4;    // --max-age-ms: a TOF's useful life, at most a minute
constexpr double kMaxDelayMs = 1e4;  // --delay-ms of accuracy runs

void add_dds_options(CLI::App* app, dds::DdsOptions& o) {
  app->add_option("--domain", o.domain_id, "DDS domain id")->transform(whole_in(0, 232));
  app->add_option("--participant-profile", o.participant_profile,
                  "participant profile of the QoS XML (default: loopback only)");
  app->add_option("--qos", o.extra_qos_files, "extra Fast DDS XML profiles file(s), loaded last")
      ->check(CLI::ExistingFile);
}

void add_source_options(CLI::App* app, SourceChoice& s) {
  auto* scenario =
      app->add_option("--scenario", s.scenario_file, "scenario YAML (default: the built-in scenario)")
          ->check(CLI::ExistingFile);
  auto* replay = app->add_option("--replay", s.replay_dir, "replay a recording in the common CSV layout")
                     ->check(CLI::ExistingDirectory);
  scenario->excludes(replay);
  app->add_option("--replay-wheel-base-m", s.replay.wheel_base_m,
                  "wheel base used to express a recording's (v, omega) as wheel velocities")
      ->transform(real_in(0.0, kMaxWheelBaseM, kOpen));
  app->add_option("--replay-odometry-k-v", s.replay.odometry_k_v_m,
                  "odometry noise reported with replayed samples: sigma_v^2 = k_v |v| / dT per wheel")
      ->transform(real_in(0.0, 1.0));
  app->add_option("--fault", s.faults,
                  "inject a fault into the simulation (repeatable): beacon_dies=ID@T, tof_outage=FROM:TO "
                  "(seconds), echoes=P");
}

void add_gateway_options(CLI::App* app, GatewayOptions& o, std::optional<std::uint64_t>& seed) {
  app->add_option("--robot", o.robot_id, "robot id the samples carry");
  app->add_option("--duration-s", o.duration_s,
                  "seconds of data to run (0: a recording to its end, a simulation until stopped)")
      ->transform(real_in(0.0, kMaxDurationS));
  app->add_option("--speed", o.speed, "data seconds per wall-clock second")
      ->transform(real_in(GatewayOptions::kMinSpeed, GatewayOptions::kMaxSpeed));  // the gateway's own bounds
  app->add_option("--seed", seed, "random seed of the simulated noise (default: the scenario's)")
      ->transform(any_unsigned());
  app->add_option("--truth-out", o.truth_csv, "write ground truth CSV here");
}

void add_decoder_options(CLI::App* app, TofDecoderConfig& o, double& max_age_ms) {
  app->add_option("--min-range-m", o.min_range_m, "shortest plausible range")
      ->transform(real_in(0.0, kMaxRangeM));
  app->add_option("--max-range-m", o.max_range_m, "longest plausible range")
      ->transform(real_in(0.0, kMaxRangeM, kOpen));
  app->add_option("--range-sigma-m", o.range_sigma_m, "standard deviation of a range")
      ->transform(real_in(0.0, 100.0, kOpen));
  app->add_option("--range-scale", o.range_scale, "ranging calibration: range = c * tof / scale")
      ->transform(real_in(0.1, 10.0));
  app->add_option("--max-age-ms", max_age_ms, "a TOF fired this long before the newest is stale")
      ->transform(real_in(0.0, kMaxAgeMs, kOpen));
}

// with_robot_filter / with_circle: false where --robot names the simulated robot and the source
// gives the receivers (demo, run).
void add_localizer_options(CLI::App* app, LocalizerSettings& o, bool standalone) {
  app->add_option("--estimator", o.estimator, "estimator plugin (see beaconloc localizer --list-estimators)");
  app->add_option("--receivers", o.receivers, "receivers in the robot frame, x:y[,x:y...] (m)");
  app->add_option("--param", o.parameters, "estimator parameter NAME=VALUE (repeatable)");
  app->add_option("--map", o.map_file,
                  "occupancy grid for laser models, ROS map_server YAML + PGM (default in run and demo: the "
                  "scenario's map)")
      ->check(CLI::ExistingFile);
  app->add_option("--initial-pose", o.initial_pose,
                  "X Y YAW: where the robot starts, for estimators placed by hand (default in run and demo: "
                  "the scenario's start)")
      ->expected(3)
      ->transform(real_in(-kMaxMapCoordinateM, kMaxMapCoordinateM));
  if (!standalone) return;
  app->add_option("--robot", o.robot, "serve only this robot id (default: every robot)");
  app->add_option("--receiver-radius-m", o.receiver_radius_m,
                  "without --receivers: receivers on a circle of this radius")
      ->transform(real_in(0.0, kMaxReceiverOffsetM, kOpen));
  app->add_option("--receiver-count", o.receiver_count,
                  "without --receivers: number of receivers on the circle")
      ->transform(whole_in(1, 16));
  app->add_option("--receiver-height-m", o.receiver_height_m, "receivers' height above the floor")
      ->transform(real_in(-kMaxReceiverOffsetM, kMaxReceiverOffsetM));
}

void add_bridge_options(CLI::App* app, bridge::BridgeOptions& o, LocalizerSettings& receivers) {
  app->add_option("--robot", o.robot_id, "the robot whose estimates and odometry this bridge speaks for");
  app->add_option("--namespace", o.ros_namespace, "ROS 2 namespace: rt/<ns>/beacon_pose (default: none)");
  app->add_option("--map-frame", o.map_frame, "map frame (REP-105)");
  app->add_option("--odom-frame", o.odom_frame, "odometry frame (REP-105)");
  app->add_option("--base-frame", o.base_frame, "robot base frame (REP-105)");
  app->add_option("--receivers", receivers.receivers, "receivers in the robot frame, x:y[,x:y...] (m)");
  app->add_option("--receiver-height-m", receivers.receiver_height_m, "receivers' height above the floor")
      ->transform(real_in(-kMaxReceiverOffsetM, kMaxReceiverOffsetM));
  app->add_flag("--odom-in", o.odometry_in,
                "feed the localizer from rt/<ns>/odom (nav_msgs/Odometry of the robot's driver)");
  app->add_flag("--scan-in", o.scan_in, "feed the localizer from rt/<ns>/scan (sensor_msgs/LaserScan)");
  app->add_option("--wheel-base-m", o.wheel_base_m,
                  "wheel base to express the driver's twist as wheel speeds")
      ->transform(real_in(0.0, kMaxWheelBaseM, kOpen));
}

void run_until_stopped() {
  while (!dds::wait_for_stop(1s)) {
  }
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"beaconloc: localization of robots against ultrasonic ceiling beacons, over Fast DDS"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "beaconloc 0.1.0");

  dds::DdsOptions dds_options;
  SourceChoice source_choice;
  GatewayOptions gateway_options;
  std::optional<std::uint64_t> seed;
  TofDecoderConfig decoder_config;
  double max_age_ms = static_cast<double>(TofDecoderConfig{}.max_age_ns) / 1e6;
  LocalizerSettings localizer_settings;
  bool list_estimators = false;
  std::string out_dir;
  bool processes = false;
  double monitor_duration_s = 0.0;
  std::string truth_file, estimate_file, beacons_file;
  double max_truth_gap_s = 0.5;

  auto* gateway =
      app.add_subcommand("gateway", "beacon-gateway: publish the beacon map, TOFs, odometry and scans");
  add_dds_options(gateway, dds_options);
  add_source_options(gateway, source_choice);
  add_gateway_options(gateway, gateway_options, seed);

  auto* decoder = app.add_subcommand("decoder", "decoder: RawTof -> BeaconRange, refusing bad TOFs");
  add_dds_options(decoder, dds_options);
  add_decoder_options(decoder, decoder_config, max_age_ms);

  auto* localizer =
      app.add_subcommand("localizer", "localizer: odometry + ranges -> pose, one estimator plugin");
  add_dds_options(localizer, dds_options);
  add_localizer_options(localizer, localizer_settings, true);
  localizer->add_flag("--list-estimators", list_estimators, "print the estimators and exit");

  bridge::BridgeOptions bridge_options;
  LocalizerSettings bridge_receivers;
  auto* bridge_cmd = app.add_subcommand(
      "bridge",
      "ROS 2 bridge: estimates, map -> odom, beacons and ranges as ROS 2 topics; a ROS 2 robot's odom "
      "and scan in");
  add_dds_options(bridge_cmd, dds_options);
  add_bridge_options(bridge_cmd, bridge_options, bridge_receivers);
  std::string bridge_beacons_file;
  bridge_cmd
      ->add_option("--beacons", bridge_beacons_file,
                   "beacons CSV (beacon_id,x_m,y_m,z_m) to draw when no gateway publishes the beacon map")
      ->check(CLI::ExistingFile);
  bool with_bridge = false;

  auto* demo =
      app.add_subcommand("demo", "the whole pipeline in one process on the built-in scenario, in real time");
  demo->add_flag("--bridge", with_bridge,
                 "also run the ROS 2 bridge in this process (ROS 2 tools see the demo)");
  add_dds_options(demo, dds_options);
  add_gateway_options(demo, gateway_options, seed);
  add_localizer_options(demo, localizer_settings, false);
  demo->add_option("--out", out_dir, "write truth, estimates, metrics and plots into this directory");

  auto* run_cmd = app.add_subcommand(
      "run",
      "gateway, decoder and localizer over DDS on a scenario or a recording, as fast as they go; "
      "writes truth.csv, estimate.csv, metrics.json and plots");
  add_dds_options(run_cmd, dds_options);
  add_source_options(run_cmd, source_choice);
  add_gateway_options(run_cmd, gateway_options, seed);
  add_decoder_options(run_cmd, decoder_config, max_age_ms);
  add_localizer_options(run_cmd, localizer_settings, false);
  run_cmd->add_option("--out", out_dir, "output directory")->required();
  run_cmd->add_flag("--processes", processes, "one process per participant (needs --speed)");
  run_cmd->add_flag("--bridge", with_bridge, "also run the ROS 2 bridge (in the run's process)");

  auto* eval =
      app.add_subcommand("eval", "score an estimate CSV against a truth CSV: metrics.json and plots");
  eval->add_option("--truth", truth_file, "truth CSV (stamp_ns,x_m,y_m,yaw_rad)")
      ->required()
      ->check(CLI::ExistingFile);
  eval->add_option("--estimate", estimate_file, "estimate CSV written by run or demo")
      ->required()
      ->check(CLI::ExistingFile);
  eval->add_option("--out", out_dir, "output directory")->required();
  eval->add_option("--beacons", beacons_file, "beacons CSV to draw (beacon_id,x_m,y_m,z_m)")
      ->check(CLI::ExistingFile);
  eval->add_option("--max-truth-gap-s", max_truth_gap_s, "interpolate truth over gaps up to this long")
      ->transform(real_in(0.0, 3600.0, kOpen));

  std::vector<std::string> accuracy_scenarios, accuracy_estimators{"range_ekf"}, accuracy_parameters;
  int accuracy_seeds = 10;
  std::uint64_t accuracy_first_seed = 1;
  double accuracy_settle_s = 0.0;
  std::optional<double> accuracy_odometry_k_v_m;
  std::string accuracy_table = "pose";
  std::string accuracy_out;
  auto* accuracy = app.add_subcommand(
      "accuracy",
      "accuracy over seeds, without DDS: a markdown table of mean and spread per scenario and estimator");
  accuracy->add_option("--scenario", accuracy_scenarios, "scenario YAML (repeatable)")
      ->required()
      ->check(CLI::ExistingFile);
  accuracy->add_option("--estimator", accuracy_estimators, "estimator (repeatable; default range_ekf)");
  accuracy->add_option("--seeds", accuracy_seeds, "number of seeds")->transform(whole_in(1, 1000));
  accuracy->add_option("--first-seed", accuracy_first_seed, "first seed")->transform(any_unsigned());
  accuracy->add_option("--settle-s", accuracy_settle_s, "seconds after the first pose not scored")
      ->transform(real_in(0.0, kMaxDurationS));
  accuracy->add_option("--param", accuracy_parameters, "estimator parameter NAME=VALUE for every estimator");
  accuracy
      ->add_option("--odometry-k-v-m", accuracy_odometry_k_v_m,
                   "replace the scenarios' odometry noise k_v (sigma_v^2 = k_v |v| / dT per wheel)")
      ->transform(real_in(0.0, 1.0));
  accuracy
      ->add_option("--table", accuracy_table,
                   "pose: E_p, E_phi, E_S, NEES (seed 000 Table II); distance: mean, std, RMSE, max of the "
                   "position error and the association rates (seed 001 Tables 4-7)")
      ->check(CLI::IsMember({"pose", "distance"}));
  accuracy->add_option("--out", accuracy_out, "also write the table to this file");
  std::vector<std::string> accuracy_faults;
  double accuracy_delay_ms = 0.0;
  accuracy->add_option(
      "--fault", accuracy_faults,
      "also score the scenarios with this fault (repeatable, all at once): beacon_dies=ID@T, "
      "tof_outage=FROM:TO, echoes=P; the clean row comes first");
  accuracy
      ->add_option("--delay-ms", accuracy_delay_ms,
                   "also score with every TOF and scan delivered late by a uniform random 0..D ms "
                   "(odometry on time); the in-order row comes first")
      ->transform(real_in(0.0, kMaxDelayMs));

  auto* monitor = app.add_subcommand(
      "monitor",
      "print each robot's newest pose every second and each participant's health as it changes (gone or "
      "silent when it stopped or died); at the end, every participant's counts and the robots served by "
      "two localizers; with --truth, the accuracy");
  add_dds_options(monitor, dds_options);
  monitor->add_option("--duration-s", monitor_duration_s, "stop after this many seconds (0: until stopped)")
      ->transform(real_in(0.0, kMaxDurationS));
  monitor->add_option("--truth", truth_file, "ground truth CSV written by the gateway");
  monitor->add_option("--out", estimate_file, "write every pose to this CSV at the end");

  CLI11_PARSE(app, argc, argv);
  // The commands that run participants poll the stop flag and stop cleanly (their DDS entities
  // and shared-memory files released). The offline ones (eval, accuracy) poll nothing and hold
  // no DDS entity: a stop signal keeps its default action and ends them at once.
  if (!eval->parsed() && !accuracy->parsed()) dds::install_stop_handlers();
  decoder_config.max_age_ns = static_cast<StampNs>(max_age_ms * 1e6);

  try {
    if (gateway->parsed()) {
      LoadedSource source = load_source(source_choice, seed);
      gateway_options.seed = source.seed;
      GatewayParticipant participant(dds_options, gateway_options, std::move(source.source));
      participant.start();
      while (!participant.finished() && !dds::wait_for_stop(100ms)) {
      }
      participant.stop();
      participant.rethrow_failure();
      return 0;
    }
    if (bridge_cmd->parsed()) {
      bridge_options.receivers = bridge_receivers.config().receivers;
      if (!bridge_beacons_file.empty()) bridge_options.beacons = load_beacon_map_csv(bridge_beacons_file);
      bridge::BridgeParticipant participant(dds_options, bridge_options);
      run_until_stopped();
      return 0;
    }
    if (decoder->parsed()) {
      DecoderParticipant participant(dds_options, decoder_config);
      run_until_stopped();
      return 0;
    }
    if (localizer->parsed()) {
      if (list_estimators) {
        for (const auto& name : EstimatorRegistry::instance().names()) {
          std::cout << name << "  " << EstimatorRegistry::instance().description(name) << '\n';
        }
        return 0;
      }
      LocalizerParticipant participant(
          dds_options,
          LocalizerCore(localizer_settings.estimator, localizer_settings.config(), localizer_settings.robot));
      run_until_stopped();
      return 0;
    }
    if (eval->parsed()) {
      const Metrics m = evaluate_files(truth_file, estimate_file, out_dir, beacons_file, max_truth_gap_s);
      std::cout << format_metrics(m) << "\nwrote " << out_dir << "/metrics.json, trajectory.svg, error.svg\n";
      return m.samples ? 0 : 1;
    }
    if (accuracy->parsed()) {
      std::vector<AccuracyRow> rows;
      std::vector<std::string> failed_runs;
      const bool variants_compared = !accuracy_faults.empty() || accuracy_delay_ms > 0.0;
      for (const auto& file : accuracy_scenarios) {
        sim::Scenario clean = sim::load_scenario_file(file);
        if (accuracy_odometry_k_v_m) clean.odometry_k_v_m = *accuracy_odometry_k_v_m;
        // The clean, in-order row, then the same seeds with the faults and the delay.
        struct Variant {
          std::string label;
          sim::Scenario scenario;
          Delivery delivery;
        };
        std::vector<Variant> variants{{clean.name, clean, {}}};
        if (variants_compared) {
          Variant v{clean.name, clean, {}};
          for (const auto& fault : accuracy_faults) {
            sim::apply_fault(v.scenario, fault);
            v.label += " + " + fault;
          }
          if (accuracy_delay_ms > 0.0) {
            v.delivery.max_measurement_delay_ns = s_to_ns(accuracy_delay_ms * 1e-3);
            std::ostringstream label;
            label << " + delay 0.." << accuracy_delay_ms << " ms";
            v.label += label.str();
          }
          variants.push_back(v);
        }
        for (const auto& estimator : accuracy_estimators) {
          for (const auto& variant : variants) {
            AccuracyRow row{variant.label, estimator, {}, {}, {}};
            for (int k = 0; k < accuracy_seeds; ++k) {
              const OfflineRunResult r =
                  run_scenario_offline(variant.scenario, accuracy_first_seed + static_cast<std::uint64_t>(k),
                                       estimator, accuracy_parameters, accuracy_settle_s, variant.delivery);
              if (r.metrics.samples == 0) {  // a run that gave nothing is no 0 m: a failure
                failed_runs.push_back(variant.label + ", " + estimator + ", seed " +
                                      std::to_string(accuracy_first_seed + static_cast<std::uint64_t>(k)) +
                                      ": " + std::to_string(r.poses) + " pose(s), none scored");
                continue;
              }
              row.runs.push_back(r.metrics);
              if (r.associations.total()) row.associations.push_back(r.associations);
              for (const auto& [reason, n] : r.rejections.rejected_by_reason()) row.rejections[reason] += n;
            }
            rows.push_back(row);
          }
        }
      }
      const std::string table =
          accuracy_table == "distance" ? distance_table_markdown(rows) : accuracy_table_markdown(rows);
      // The file first: a reader of stdout that leaves early (`| head`) ends the command (SIGPIPE).
      if (!accuracy_out.empty()) {
        std::ofstream out(accuracy_out);
        out << table;
        if (!out.flush()) throw std::runtime_error("writing '" + accuracy_out + "' failed");
      }
      std::cout << table;
      if (variants_compared) {
        // What the faults cost: the typed refusals of the decoder and localizer, over all seeds.
        std::cout << "\nrefusals summed over the seeds:\n";
        for (const auto& row : rows) {
          std::cout << "- " << row.scenario << ", " << row.estimator << ":";
          if (row.rejections.empty()) std::cout << " none";
          for (const auto& [reason, n] : row.rejections) std::cout << ' ' << reason << '=' << n;
          std::cout << '\n';
        }
      }
      if (!failed_runs.empty()) {
        std::cerr << "beaconloc accuracy: " << failed_runs.size()
                  << " run(s) gave no scored pose, left out of "
                  << "the table:\n";
        for (const auto& f : failed_runs) std::cerr << "- " << f << '\n';
        return 1;
      }
      return 0;
    }
    if (monitor->parsed()) {
      return run_monitor({dds_options, monitor_duration_s, truth_file, estimate_file});
    }
    if (demo->parsed() || run_cmd->parsed()) {
      PipelineOptions o;
      o.dds = dds_options;
      o.decoder = decoder_config;
      o.localizer = localizer_settings;
      o.out_dir = out_dir;
      o.processes = processes;
      if (with_bridge && processes) {
        throw std::invalid_argument(
            "--bridge runs in the run's process; with --processes start `beaconloc bridge`");
      }
      if (with_bridge) o.bridge = bridge::BridgeOptions{};
      LoadedSource source = load_source(source_choice, seed);
      o.gateway = gateway_options;
      o.gateway.seed = source.seed;
      if (demo->parsed()) {
        if (demo->count("--duration-s") == 0) o.gateway.duration_s = 20.0;
        o.print_poses = true;
      } else {
        if (run_cmd->count("--speed") == 0)
          o.gateway.speed = processes ? 10.0 : 0.0;  // 0: as fast as it goes
        if (run_cmd->count("--duration-s") == 0 && source.scenario)
          o.gateway.duration_s = source.scenario->duration_s;
        // A scenario states its beacon system's range limits and noise; the decoder takes them
        // unless told otherwise (its defaults are seed 000's: seed 001's ranges reach 14 m).
        if (source.scenario) {
          if (run_cmd->count("--min-range-m") == 0) o.decoder.min_range_m = source.scenario->min_range_m;
          if (run_cmd->count("--max-range-m") == 0) o.decoder.max_range_m = source.scenario->max_range_m;
          if (run_cmd->count("--range-sigma-m") == 0)
            o.decoder.range_sigma_m = source.scenario->range_sigma_m;
        }
        o.print_progress = true;
      }
      if (!out_dir.empty() && o.gateway.truth_csv.empty() && !processes)
        o.gateway.truth_csv = out_dir + "/truth.csv";
      if (run_cmd->parsed()) {
        o.gateway.wall_clock_stamps = false;  // the same seed gives byte-identical files
        if (!processes) o.gateway.record_dir = out_dir;
      }
      std::cout << "beaconloc " << (demo->parsed() ? "demo" : "run") << ": " << source.label << ", estimator "
                << o.localizer.estimator << ", seed " << source.seed << '\n';
      std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe");
      const PipelineResult r = run_pipeline(o, std::move(source), self.string());
      std::cout << r.diagnostics;
      // No pose at all is a failure; poses that no truth covers are a failure only where the
      // source has truth (then the estimate and the truth do not overlap). A source without
      // ground truth (a replay without gt.csv) gives poses that are not scored.
      const bool has_truth = r.truth_samples > 0;
      std::printf("poses: %zu at %.1f Hz; %s\n", r.poses, r.pose_rate_hz,
                  has_truth ? format_metrics(r.metrics).c_str() : "no ground truth: not scored");
      if (!out_dir.empty())
        std::cout << "wrote " << out_dir
                  << "/{truth,estimate,beacons}.csv, metrics.json, trajectory.svg, error.svg\n";
      if (r.poses == 0) {
        std::cerr << "beaconloc: no pose was estimated (the localizer's last status is above)\n";
        return 1;
      }
      if (has_truth && r.metrics.samples == 0) {
        std::cerr << "beaconloc: no pose was at a stamp the ground truth covers\n";
        return 1;
      }
      return 0;
    }
  } catch (const std::exception& e) {
    std::cerr << "beaconloc: error: " << e.what() << '\n';
    return 2;
  }
  return 0;
}

}  // namespace beaconloc::cli

int main(int argc, char** argv) { return beaconloc::cli::run(argc, argv); }
