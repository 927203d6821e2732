// beaconloc: one executable, one subcommand per participant (gateway, decoder, localizer), the
// whole pipeline in one process (demo), and a monitor of the poses.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <thread>

#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "decoder_participant.hpp"
#include "diagnostics_recorder.hpp"
#include "gateway_participant.hpp"
#include "localizer_participant.hpp"
#include "pose_recorder.hpp"
#include "sim/scenario.hpp"

namespace beaconloc::cli {
namespace {

using namespace std::chrono_literals;

// Validators whose messages name the rule, not the limits of a double.
const CLI::Validator kPositive(
    [](std::string& v) {
      try {
        return std::stod(v) > 0.0 ? std::string() : "must be > 0, got " + v;
      } catch (const std::exception&) {
        return "not a number: " + v;
      }
    },
    "POSITIVE");
const CLI::Validator kNonNegative(
    [](std::string& v) {
      try {
        return std::stod(v) >= 0.0 ? std::string() : "must be >= 0, got " + v;
      } catch (const std::exception&) {
        return "not a number: " + v;
      }
    },
    "NON-NEGATIVE");

void add_dds_options(CLI::App* app, dds::DdsOptions& o) {
  app->add_option("--domain", o.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  app->add_option("--participant-profile", o.participant_profile,
                  "participant profile of the QoS XML (default: loopback only)");
  app->add_option("--qos", o.extra_qos_files, "extra Fast DDS XML profiles file(s), loaded last")
      ->check(CLI::ExistingFile);
}

void add_gateway_options(CLI::App* app, GatewayOptions& o) {
  app->add_option("--robot", o.robot_id, "robot id the samples carry");
  app->add_option("--duration-s", o.duration_s, "simulated seconds to run (0: until stopped)")
      ->check(kNonNegative);
  app->add_option("--speed", o.speed, "simulated seconds per wall-clock second")->check(kPositive);
  app->add_option("--seed", o.seed, "random seed of the simulated noise");
  app->add_option("--truth-out", o.truth_csv, "write ground truth CSV here");
}

struct LocalizerCliOptions {
  std::string estimator = "range_ekf";
  std::string robot;  // empty: every robot
  double receiver_radius_m = 0.19;
  int receiver_count = 3;
  std::vector<std::string> parameters;

  EstimatorConfig config() const {
    EstimatorConfig c;
    c.receivers = ReceiverArray::on_circle(receiver_radius_m, receiver_count);
    for (const auto& p : parameters) {
      const auto eq = p.find('=');
      if (eq == std::string::npos || eq == 0) {
        throw std::invalid_argument("--param '" + p + "' is not NAME=VALUE");
      }
      try {
        std::size_t used = 0;
        const std::string value = p.substr(eq + 1);
        c.parameters[p.substr(0, eq)] = std::stod(value, &used);
        if (used != value.size()) throw std::invalid_argument(value);
      } catch (const std::exception&) {
        throw std::invalid_argument("--param '" + p + "': value is not a number");
      }
    }
    return c;
  }
};

// with_robot_filter: false where --robot already names the simulated robot (demo).
void add_localizer_options(CLI::App* app, LocalizerCliOptions& o, bool with_robot_filter) {
  app->add_option("--estimator", o.estimator, "estimator plugin (see --list-estimators)");
  if (with_robot_filter) {
    app->add_option("--robot", o.robot, "serve only this robot id (default: every robot)");
  }
  app->add_option("--receiver-radius-m", o.receiver_radius_m, "receivers on a circle of this radius")
      ->check(kPositive);
  app->add_option("--receiver-count", o.receiver_count, "number of receivers on the circle")
      ->check(CLI::Range(1, 16));
  app->add_option("--param", o.parameters, "estimator parameter NAME=VALUE (repeatable)");
}

void add_decoder_options(CLI::App* app, TofDecoderConfig& o, double& max_age_ms) {
  app->add_option("--min-range-m", o.min_range_m, "shortest plausible range")->check(kNonNegative);
  app->add_option("--max-range-m", o.max_range_m, "longest plausible range")->check(kPositive);
  app->add_option("--range-sigma-m", o.range_sigma_m, "standard deviation of a range")->check(kPositive);
  app->add_option("--max-age-ms", max_age_ms, "a TOF fired this long before the newest is stale")
      ->check(kPositive);
}

void run_until_stopped() {
  while (!dds::wait_for_stop(1s)) {
  }
}

void print_summary(const PoseRunSummary& s, std::ostream& out) {
  char line[256];
  std::snprintf(line, sizeof line,
                "poses: %zu at %.1f Hz; against ground truth (%zu poses): position RMS %.3f m, "
                "mean %.3f m, max %.3f m; heading RMS %.2f deg\n",
                s.poses, s.pose_rate_hz, s.error.samples(), s.error.position_rms_m(),
                s.error.position_mean_m(), s.error.position_max_m(), s.error.heading_rms_deg());
  out << line;
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"beaconloc: localization of robots against ultrasonic ceiling beacons, over Fast DDS"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "beaconloc 0.1.0");

  dds::DdsOptions dds_options;
  GatewayOptions gateway_options;
  TofDecoderConfig decoder_config;
  double max_age_ms = 600.0;
  LocalizerCliOptions localizer_options;
  bool list_estimators = false;
  std::string demo_out;
  double monitor_duration_s = 0.0;
  std::string monitor_truth, monitor_out;

  auto* gateway = app.add_subcommand(
      "gateway", "beacon-gateway: publish the beacon map, TOFs and odometry (simulated source)");
  add_dds_options(gateway, dds_options);
  add_gateway_options(gateway, gateway_options);
  std::string source = "sim";
  gateway->add_option("--source", source, "data source")->check(CLI::IsMember({"sim"}));

  auto* decoder = app.add_subcommand("decoder", "decoder: RawTof -> BeaconRange, rejecting bad TOFs");
  add_dds_options(decoder, dds_options);
  add_decoder_options(decoder, decoder_config, max_age_ms);

  auto* localizer =
      app.add_subcommand("localizer", "localizer: odometry + ranges -> pose, one estimator plugin");
  add_dds_options(localizer, dds_options);
  add_localizer_options(localizer, localizer_options, true);
  localizer->add_flag("--list-estimators", list_estimators, "print the estimators and exit");

  auto* demo = app.add_subcommand(
      "demo", "the whole pipeline in one process on the built-in scenario; prints the accuracy");
  add_dds_options(demo, dds_options);
  add_gateway_options(demo, gateway_options);
  add_localizer_options(demo, localizer_options, false);
  demo->add_option("--out", demo_out, "write truth.csv and estimate.csv into this directory");
  gateway_options.duration_s = 0.0;
  demo->callback([&] {
    if (gateway_options.duration_s == 0.0) gateway_options.duration_s = 20.0;  // demo default
    if (!demo_out.empty()) {
      std::filesystem::create_directories(demo_out);
      if (gateway_options.truth_csv.empty()) gateway_options.truth_csv = demo_out + "/truth.csv";
    }
  });

  auto* monitor = app.add_subcommand(
      "monitor", "print the poses on the bus each second; with --truth, the accuracy at the end");
  add_dds_options(monitor, dds_options);
  monitor->add_option("--duration-s", monitor_duration_s, "stop after this many seconds (0: until stopped)")
      ->check(kNonNegative);
  monitor->add_option("--truth", monitor_truth, "ground truth CSV written by the gateway");
  monitor->add_option("--out", monitor_out, "write the poses to this CSV");

  CLI11_PARSE(app, argc, argv);
  dds::install_stop_handlers();

  try {
    if (gateway->parsed()) {
      GatewayParticipant participant(dds_options, gateway_options, sim::default_scenario());
      participant.start();
      while (!participant.finished() && !dds::wait_for_stop(100ms)) {
      }
      participant.stop();
      participant.rethrow_failure();
      return 0;
    }
    if (decoder->parsed()) {
      decoder_config.max_age_ns = static_cast<StampNs>(max_age_ms * 1e6);
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
          LocalizerCore(localizer_options.estimator, localizer_options.config(), localizer_options.robot));
      run_until_stopped();
      return 0;
    }
    if (monitor->parsed()) {
      TruthTrack truth;
      if (!monitor_truth.empty()) truth = load_truth_csv(monitor_truth);
      PoseRecorder recorder(dds_options);
      DiagnosticsRecorder diagnostics(dds_options);
      const auto start = std::chrono::steady_clock::now();
      std::size_t shown = 0;
      while (!dds::wait_for_stop(1s)) {
        const auto poses = recorder.poses();
        if (poses.size() > shown) {
          const auto& p = poses.back();
          std::printf("%s %s: %zu poses (+%zu), x %.3f m, y %.3f m, yaw %.1f deg, %s\n", p.robot_id.c_str(),
                      p.estimator.c_str(), poses.size(), poses.size() - shown, p.estimate.pose_map_base.x(),
                      p.estimate.pose_map_base.y(), p.estimate.pose_map_base.z() * 180.0 / M_PI,
                      to_string(p.estimate.status));
          std::fflush(stdout);
          shown = poses.size();
        }
        if (monitor_duration_s > 0.0 &&
            std::chrono::steady_clock::now() - start > std::chrono::duration<double>(monitor_duration_s)) {
          break;
        }
      }
      if (!monitor_truth.empty()) truth = load_truth_csv(monitor_truth);  // the gateway kept writing
      const auto poses = recorder.poses();
      if (!monitor_out.empty()) write_poses_csv(monitor_out, poses);
      print_diagnostics(diagnostics.latest(), std::cout);
      print_summary(summarize(poses, truth), std::cout);
      return 0;
    }
    if (demo->parsed()) {
      std::mutex truth_mutex;
      TruthTrack truth;
      LocalizerParticipant localizer_participant(
          dds_options,
          LocalizerCore(localizer_options.estimator, localizer_options.config(), localizer_options.robot));
      DecoderParticipant decoder_participant(dds_options, decoder_config);
      PoseRecorder recorder(dds_options);
      DiagnosticsRecorder diagnostics(dds_options);
      GatewayParticipant gateway_participant(dds_options, gateway_options, sim::default_scenario(),
                                             [&](StampNs stamp, const Pose2& pose) {
                                               std::lock_guard<std::mutex> lock(truth_mutex);
                                               truth.add(stamp, pose);
                                             });
      std::cout << "beaconloc demo: " << sim::default_scenario().name << ", estimator "
                << localizer_options.estimator << ", " << gateway_options.duration_s << " s simulated at x"
                << gateway_options.speed << '\n';
      gateway_participant.start();
      double next_report_s = 1.0;
      const auto start = std::chrono::steady_clock::now();
      while (!gateway_participant.finished() && !dds::wait_for_stop(100ms)) {
        const double elapsed_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() *
            gateway_options.speed;
        if (elapsed_s >= next_report_s) {
          const auto poses = recorder.poses();
          if (!poses.empty()) {
            const auto& p = poses.back().estimate;
            std::printf("t=%5.1f s  pose x %.3f m  y %.3f m  yaw %6.1f deg  %s\n", elapsed_s,
                        p.pose_map_base.x(), p.pose_map_base.y(), p.pose_map_base.z() * 180.0 / M_PI,
                        to_string(p.status));
          } else {
            std::printf("t=%5.1f s  no pose yet (initializing from beacons)\n", elapsed_s);
          }
          std::fflush(stdout);
          next_report_s += 1.0;
        }
      }
      gateway_participant.stop();
      gateway_participant.rethrow_failure();
      std::this_thread::sleep_for(300ms);  // let the last samples through the pipeline
      const auto poses = recorder.poses();
      std::lock_guard<std::mutex> lock(truth_mutex);
      if (!demo_out.empty()) {
        write_poses_csv(demo_out + "/estimate.csv", poses);
      }
      const PoseRunSummary summary = summarize(poses, truth);
      print_diagnostics(diagnostics.latest(), std::cout);
      print_summary(summary, std::cout);
      if (summary.error.samples() == 0) {
        std::cerr << "beaconloc demo: no pose was estimated\n";
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
