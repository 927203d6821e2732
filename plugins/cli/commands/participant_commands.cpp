// The commands that run one participant until stopped: gateway, decoder, localizer, bridge, and
// the monitor that watches them.
#include <chrono>
#include <iostream>

#include "beaconloc/core/csv_reader.hpp"
#include "beaconloc/core/estimator_registry.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "bridge_participant.hpp"
#include "command.hpp"
#include "decoder_participant.hpp"
#include "estimator_plugins.hpp"
#include "localizer_participant.hpp"
#include "monitor.hpp"
#include "number_options.hpp"
#include "options.hpp"
#include "serial_source.hpp"

namespace beaconloc::cli {
namespace {

using namespace std::chrono_literals;

void run_until_stopped() {
  while (!dds::wait_for_stop(1s)) {
  }
}

class GatewayCommand : public Command {
 public:
  explicit GatewayCommand(CLI::App& app)
      : Command(app.add_subcommand("gateway", "beacon-gateway: publish the beacon map, TOFs, odometry and scans")) {
    dds_option_set(dds_).add_to(app_);
    const std::vector<CLI::Option*> source = source_option_set(source_).add_to(app_);
    source[0]->excludes(source[1]);  // --scenario or --replay
    gateway_option_set(gateway_, seed_).add_to(app_);
    // Receiver hardware on a serial line (docs/serial-protocol.md): live, in real time.
    CLI::Option* serial_device =
        app_->add_option("--serial", serial_.device, "read receiver modules on this serial device (e.g. /dev/ttyUSB0)");
    serial_device->excludes(source[0])->excludes(source[1]);
    app_->add_option("--baud", serial_.baud, "the serial line's baud rate")->needs(serial_device);
    app_->add_option("--serial-protocol", serial_protocol_, "beaconloc (our frames) or marvelmind (raw distances)")
        ->check(CLI::IsMember({"beaconloc", "marvelmind"}))
        ->needs(serial_device);
    app_->add_option("--beacons", beacons_file_, "the site's beacons CSV (beacon_id,x_m,y_m,z_m): needed with --serial")
        ->check(CLI::ExistingFile)
        ->needs(serial_device);
    app_->add_option("--temperature-c", serial_.temperature_c,
                     "air temperature for TOFs that carry none (and Marvelmind distances' reference)")
        ->transform(real_in(-100.0, 100.0))
        ->needs(serial_device);
    app_->add_option("--odometry-k-v", serial_.odometry_k_v_m,
                     "odometry noise reported with the line's wheel speeds: sigma^2 = k_v |v| / dT per wheel")
        ->transform(real_in(0.0, 1.0))
        ->needs(serial_device);
  }
  int execute() override {
    std::unique_ptr<Source> source;
    if (!serial_.device.empty()) {
      if (beacons_file_.empty()) throw std::invalid_argument("--serial needs --beacons: the line does not carry the map");
      if (given("--speed") && gateway_.speed != 1.0) {
        throw std::invalid_argument("--serial is live: --speed must be 1");
      }
      serial_.protocol = serial_protocol_ == "marvelmind" ? serial::Protocol::kMarvelmind : serial::Protocol::kBeaconloc;
      serial_.beacons = load_beacon_map_csv(beacons_file_);
      gateway_.speed = 1.0;
      source = std::make_unique<SerialSource>(serial_, [] { return dds::wall_clock_ns(); });
    } else {
      LoadedSource loaded = load_source(source_, seed_);
      gateway_.seed = loaded.seed;
      source = std::move(loaded.source);
    }
    GatewayParticipant participant(dds_, gateway_, std::move(source));
    participant.start();
    while (!participant.finished() && !dds::wait_for_stop(100ms)) {
    }
    participant.stop();
    participant.rethrow_failure();
    return 0;
  }

 private:
  bool given(const char* flag) const { return app_->count(flag) > 0; }
  dds::DdsOptions dds_;
  SourceChoice source_;
  GatewayOptions gateway_;
  std::optional<std::uint64_t> seed_;
  SerialSourceOptions serial_;
  std::string serial_protocol_ = "beaconloc";
  std::string beacons_file_;
};

class DecoderCommand : public Command {
 public:
  explicit DecoderCommand(CLI::App& app)
      : Command(app.add_subcommand("decoder", "decoder: RawTof -> BeaconRange, refusing bad TOFs")) {
    dds_option_set(dds_).add_to(app_);
    decoder_option_set(decoder_, max_age_ms_).add_to(app_);
  }
  int execute() override {
    DecoderParticipant participant(dds_, decoder_config_with_age(decoder_, max_age_ms_));
    run_until_stopped();
    return 0;
  }

 private:
  dds::DdsOptions dds_;
  TofDecoderConfig decoder_;
  double max_age_ms_ = max_age_ms_of(decoder_);
};

class LocalizerCommand : public Command {
 public:
  explicit LocalizerCommand(CLI::App& app)
      : Command(app.add_subcommand("localizer", "localizer: odometry + ranges -> pose, one estimator plugin")) {
    dds_option_set(dds_).add_to(app_);
    localizer_option_set(settings_, true).add_to(app_);
    app_->add_flag("--list-estimators", list_estimators_, "print the estimators and exit");
    app_->add_flag("--shard", shard_,
                   "one shard of a fleet's localizers: serve the share of the robots that falls to it among "
                   "the live shards of its estimator, take over a dead shard's robots");
  }
  int execute() override {
    load_estimator_plugins(settings_.estimator_plugins);
    if (list_estimators_) {
      for (const auto& name : EstimatorRegistry::instance().names()) {
        std::cout << name << "  " << EstimatorRegistry::instance().description(name) << '\n';
      }
      return 0;
    }
    if (shard_ && !settings_.robot.empty()) {
      throw std::invalid_argument("--shard serves a share of every robot; --robot serves one: not both");
    }
    LocalizerParticipant participant(dds_, LocalizerCore(settings_.estimator, settings_.config(), settings_.robot),
                                     {settings_.calibration_file, settings_.selective_activation(), shard_});
    run_until_stopped();
    return 0;
  }

 private:
  dds::DdsOptions dds_;
  LocalizerSettings settings_;
  bool list_estimators_ = false;
  bool shard_ = false;
};

class BridgeCommand : public Command {
 public:
  explicit BridgeCommand(CLI::App& app)
      : Command(app.add_subcommand("bridge",
                                   "ROS 2 bridge: estimates, map -> odom, beacons and ranges as ROS 2 topics; a ROS 2 "
                                   "robot's odom and scan in")) {
    constexpr bool kOpen = true;
    dds_option_set(dds_).add_to(app_);
    app_->add_option("--robot", bridge_.robot_id, "the robot whose estimates and odometry this bridge speaks for");
    app_->add_option("--namespace", bridge_.ros_namespace, "ROS 2 namespace: rt/<ns>/beacon_pose (default: none)");
    app_->add_option("--map-frame", bridge_.map_frame, "map frame (REP-105)");
    app_->add_option("--odom-frame", bridge_.odom_frame, "odometry frame (REP-105)");
    app_->add_option("--base-frame", bridge_.base_frame, "robot base frame (REP-105)");
    app_->add_option("--receivers", receivers_.receivers, "receivers in the robot frame, x:y[,x:y...] (m)");
    app_->add_option("--receiver-height-m", receivers_.receiver_height_m, "receivers' height above the floor")
        ->transform(real_in(-kMaxReceiverOffsetM, kMaxReceiverOffsetM));
    app_->add_flag("--odom-in", bridge_.odometry_in,
                   "feed the localizer from rt/<ns>/odom (nav_msgs/Odometry of the robot's driver)");
    app_->add_flag("--scan-in", bridge_.scan_in, "feed the localizer from rt/<ns>/scan (sensor_msgs/LaserScan)");
    app_->add_option("--wheel-base-m", bridge_.wheel_base_m, "wheel base to express the driver's twist as wheel speeds")
        ->transform(real_in(0.0, kMaxWheelBaseM, kOpen));
    app_->add_option("--beacons", beacons_file_,
                     "beacons CSV (beacon_id,x_m,y_m,z_m) to draw when no gateway publishes the beacon map")
        ->check(CLI::ExistingFile);
  }
  int execute() override {
    bridge_.receivers = receivers_.config().receivers;
    if (!beacons_file_.empty()) bridge_.beacons = load_beacon_map_csv(beacons_file_);
    bridge::BridgeParticipant participant(dds_, bridge_);
    run_until_stopped();
    return 0;
  }

 private:
  dds::DdsOptions dds_;
  bridge::BridgeOptions bridge_;
  LocalizerSettings receivers_;  // its receivers only
  std::string beacons_file_;
};

class MonitorCommand : public Command {
 public:
  explicit MonitorCommand(CLI::App& app)
      : Command(app.add_subcommand(
            "monitor",
            "print each robot's newest pose every second and each participant's health as it changes (gone or "
            "silent when it stopped or died); at the end, every participant's counts and the robots served by "
            "two localizers; with --truth, the accuracy")) {
    dds_option_set(options_.dds).add_to(app_);
    app_->add_option("--duration-s", options_.duration_s, "stop after this many seconds (0: until stopped)")
        ->transform(real_in(0.0, kMaxDurationS));
    app_->add_option("--truth", options_.truth_file, "ground truth CSV written by the gateway");
    app_->add_option("--out", options_.out_file, "write every pose to this CSV at the end");
    app_->add_flag("--fleet", options_.fleet,
                   "every second, a row per robot: pose status, pose rate, age, its gateway's rejections and the "
                   "localizer (shard) serving it");
  }
  int execute() override { return run_monitor(options_); }

 private:
  MonitorOptions options_;
};

}  // namespace

void add_participant_commands(CLI::App& app, std::vector<std::unique_ptr<Command>>& out) {
  out.push_back(std::make_unique<GatewayCommand>(app));
  out.push_back(std::make_unique<DecoderCommand>(app));
  out.push_back(std::make_unique<LocalizerCommand>(app));
  out.push_back(std::make_unique<BridgeCommand>(app));
}

void add_monitor_command(CLI::App& app, std::vector<std::unique_ptr<Command>>& out) {
  out.push_back(std::make_unique<MonitorCommand>(app));
}

}  // namespace beaconloc::cli
