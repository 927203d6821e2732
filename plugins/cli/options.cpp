#include "options.hpp"

#include <cmath>

#include "beaconloc/core/limits.hpp"
#include "number_options.hpp"

namespace beaconloc::cli {
namespace {
constexpr bool kOpen = true;       // (min, max]: the option must be > min
constexpr double kMaxAgeMs = 6e4;  // --max-age-ms: a TOF's useful life, at most a minute
}  // namespace

OptionSet dds_option_set(dds::DdsOptions& o) {
  OptionSet set;
  set.whole("--domain", o.domain_id, "DDS domain id", whole_in(0, 232))
      .text("--participant-profile", o.participant_profile,
            "participant profile of the QoS XML (default: loopback only)", {}, OptionSet::Written::kAlways)
      .texts("--qos", o.extra_qos_files, "extra Fast DDS XML profiles file(s), loaded last",
             [](CLI::Option* option) { option->check(CLI::ExistingFile); })
      .text("--keystore", o.security.keystore,
            "DDS Security on: the deployment's keystore (scripts/deployment-keys.sh; SROS2 layout)",
            [](CLI::Option* option) {
              // An empty value (`--keystore=`, `keystore: ""` in a configuration file) is no
              // keystore: refused, never taken for "unsecured".
              option->check(CLI::Validator(
                  [](std::string& dir) { return dir.empty() ? std::string("no directory given") : std::string(); },
                  "DIR"));
              option->check(CLI::ExistingDirectory);
            })
      .text("--enclave", o.security.enclave,
            "the participant's identity in the keystore (default: its role's, e.g. /beaconloc/decoder; "
            "not with run or demo, whose participants each take their own)");
  return set;
}

OptionSet source_option_set(SourceChoice& s) {
  OptionSet set;
  set.text("--scenario", s.scenario_file, "scenario YAML (default: the built-in scenario)",
           [](CLI::Option* option) { option->check(CLI::ExistingFile); })
      .text("--replay", s.replay_dir, "replay a recording in the common CSV layout",
            [](CLI::Option* option) { option->check(CLI::ExistingDirectory); })
      .real("--replay-wheel-base-m", s.replay.wheel_base_m,
            "wheel base used to express a recording's (v, omega) as wheel velocities",
            real_in(0.0, kMaxWheelBaseM, kOpen))
      .real("--replay-odometry-k-v", s.replay.odometry_k_v_m,
            "odometry distance noise reported with replayed samples: sigma^2 = k_v |v| / dT, per wheel when "
            "the recording has half_track_m, else on v",
            real_in(0.0, ReplayOptions::kMaxOdometryKvM))
      .real("--replay-heading-arw", s.replay.odometry_heading_arw_rad_per_sqrt_s,
            "heading rate noise of a recording without wheels (no half_track_m): sigma_omega^2 = N^2 / dT, "
            "N in rad/sqrt(s)",
            real_in(0.0, ReplayOptions::kMaxHeadingArwRadPerSqrtS))
      .texts("--fault", s.faults,
             "inject a fault into the simulation (repeatable): beacon_dies=ID@T, tof_outage=FROM:TO "
             "(seconds), echoes=P");
  return set;
}

OptionSet gateway_option_set(GatewayOptions& o, std::optional<std::uint64_t>& seed) {
  OptionSet set;
  set.text("--robot", o.robot_id, "robot id the samples carry", {}, OptionSet::Written::kAlways)
      .real("--duration-s", o.duration_s,
            "seconds of data to run (0: a recording to its end, a simulation until stopped)",
            real_in(0.0, kMaxDurationS))
      .real("--speed", o.speed, "data seconds per wall-clock second",
            real_in(GatewayOptions::kMinSpeed, GatewayOptions::kMaxSpeed))  // the gateway's own bounds
      .unsigned_number("--seed", seed, "random seed of the simulated noise (default: the scenario's)")
      .text("--truth-out", o.truth_csv, "write ground truth CSV here")
      .text("--firings-out", o.firings_csv,
            "write every beacon firing as CSV here (fire_stamp_ns,beacon_id,planned,heard)")
      .whole("--wait-for-readers", o.wait_for_readers,
             "before the first sample, wait for this many readers besides the run's own (for gateway: in all) on the "
             "TOF (or pulse) and odometry topics: a recorder, a second localizer",
             whole_in(0, GatewayOptions::kMaxWaitForReaders));
  return set;
}

OptionSet decoder_option_set(TofDecoderConfig& o, double& max_age_ms) {
  OptionSet set;
  set.real("--min-range-m", o.min_range_m, "shortest plausible range", real_in(0.0, kMaxRangeM))
      .real("--max-range-m", o.max_range_m, "longest plausible range", real_in(0.0, kMaxRangeM, kOpen))
      .real("--range-sigma-m", o.range_sigma_m, "standard deviation of a range", real_in(0.0, 100.0, kOpen))
      .real("--range-scale", o.range_scale, "ranging calibration: range = c * tof / scale", real_in(0.1, 10.0))
      .real("--max-age-ms", max_age_ms, "a TOF fired this long before the newest is stale",
            real_in(0.0, kMaxAgeMs, kOpen));
  return set;
}

OptionSet estimator_plugin_option_set(std::vector<std::string>& plugins) {
  OptionSet set;
  set.texts("--estimator-plugin", plugins,
            "load estimators built out of tree from this plugin file, or every *.so of this directory "
            "(repeatable; docs/deployment.md)",
            [](CLI::Option* option) { option->check(CLI::ExistingPath); });
  return set;
}

OptionSet localizer_option_set(LocalizerSettings& o, bool standalone) {
  OptionSet set;
  set.text("--estimator", o.estimator, "estimator plugin (see beaconloc localizer --list-estimators)", {},
           OptionSet::Written::kAlways)
      .options_of(estimator_plugin_option_set(o.estimator_plugins))
      .text("--receivers", o.receivers, "receivers in the robot frame, x:y[,x:y...] (m)")
      .texts("--param", o.parameters, "estimator parameter NAME=VALUE (repeatable)")
      .text("--map", o.map_file,
            "occupancy grid for laser models, ROS map_server YAML + PGM (default in run and demo: the "
            "scenario's map)",
            [](CLI::Option* option) { option->check(CLI::ExistingFile); })
      .reals("--initial-pose", o.initial_pose, 3,
             "X Y YAW: where the robot starts, for estimators placed by hand (default in run and demo: "
             "the scenario's start)",
             real_in(-kMaxMapCoordinateM, kMaxMapCoordinateM))
      .text("--firing-schedule", o.firing_schedule,
            "all: the gateways fire every beacon in turn; selective: send each robot's gateway the beacons "
            "that may reach it (seed 004 selective activation)",
            [](CLI::Option* option) { option->check(CLI::IsMember({"all", "selective"})); })
      .text("--calibration-file", o.calibration_file,
            "keep the site's beacon calibration (seed 003's calibrated groups) in this file: read at start, "
            "written whenever it changes, so it survives a restart");
  if (!standalone) return set;
  set.text("--robot", o.robot, "serve only this robot id (default: every robot)")
      .real("--receiver-radius-m", o.receiver_radius_m, "without --receivers: receivers on a circle of this radius",
            real_in(0.0, kMaxReceiverOffsetM, kOpen))
      .whole("--receiver-count", o.receiver_count, "without --receivers: number of receivers on the circle",
             whole_in(1, 16))
      .real("--receiver-height-m", o.receiver_height_m, "receivers' height above the floor",
            real_in(-kMaxReceiverOffsetM, kMaxReceiverOffsetM));
  return set;
}

TofDecoderConfig decoder_config_with_age(TofDecoderConfig o, double max_age_ms) {
  o.max_age_ns = static_cast<StampNs>(std::llround(max_age_ms * 1e6));  // exact for a value max_age_ms_of wrote
  return o;
}

double max_age_ms_of(const TofDecoderConfig& o) { return static_cast<double>(o.max_age_ns) / 1e6; }

}  // namespace beaconloc::cli
