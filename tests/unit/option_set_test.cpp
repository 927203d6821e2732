// The option groups of the beaconloc commands are defined once (plugins/cli/options.hpp): what a
// command parses, written back as arguments (what `run --processes` starts its children with),
// parses into the very same settings, bit for bit, and an option the parent did not set is not
// invented for the child.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "options.hpp"

namespace beaconloc::cli {
namespace {

struct Settings {
  dds::DdsOptions dds;
  SourceChoice source;
  GatewayOptions gateway;
  std::optional<std::uint64_t> seed;
  TofDecoderConfig decoder;
  double max_age_ms = max_age_ms_of(TofDecoderConfig{});

  std::vector<OptionSet> sets() {
    return {dds_option_set(dds), source_option_set(source), gateway_option_set(gateway, seed),
            decoder_option_set(decoder, max_age_ms)};
  }
  // Parses args (without the program name) as one command with every group.
  void parse(std::vector<std::string> args) {
    CLI::App app;
    for (const OptionSet& set : sets()) set.add_to(&app);
    std::vector<char*> argv{const_cast<char*>("beaconloc")};
    for (std::string& a : args) argv.push_back(a.data());
    app.parse(static_cast<int>(argv.size()), argv.data());
    decoder = decoder_config_with_age(decoder, max_age_ms);
  }
  std::vector<std::string> arguments() {
    std::vector<std::string> out;
    max_age_ms = max_age_ms_of(decoder);
    for (const OptionSet& set : sets()) {
      for (const std::string& a : set.arguments()) out.push_back(a);
    }
    return out;
  }
};

TEST(OptionSets, WhatACommandParsedItsChildParsesBackBitForBit) {
  const std::string scenario = std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/default.yaml";
  Settings parent;
  parent.parse({"--domain", "17", "--participant-profile", "robot.profile", "--scenario", scenario,
                "--replay-wheel-base-m", "0.12345678901234567", "--replay-odometry-k-v", "3.3e-4", "--replay-heading-arw",
                "0.0123456789012345678", "--fault",
                "echoes=0.1", "--fault", "beacon_dies=2@5", "--robot", "r7", "--duration-s",
                "12.345678901234567", "--speed", "2.5", "--seed", "18446744073709551615", "--truth-out",
                "/tmp/truth.csv", "--min-range-m", "0.1", "--max-range-m", "7.7777777777777777",
                "--range-sigma-m", "0.0123456789", "--range-scale", "1.069", "--max-age-ms", "333.3333333"});
  Settings child;
  child.parse(parent.arguments());

  EXPECT_EQ(child.dds.domain_id, 17);
  EXPECT_EQ(child.dds.participant_profile, "robot.profile");
  EXPECT_EQ(child.source.scenario_file, scenario);
  EXPECT_TRUE(child.source.replay_dir.empty());
  EXPECT_EQ(child.source.replay.wheel_base_m, parent.source.replay.wheel_base_m);
  EXPECT_EQ(child.source.replay.odometry_k_v_m, 3.3e-4);
  EXPECT_EQ(child.source.replay.odometry_heading_arw_rad_per_sqrt_s,
            parent.source.replay.odometry_heading_arw_rad_per_sqrt_s);
  EXPECT_EQ(parent.source.replay.odometry_heading_arw_rad_per_sqrt_s, 0.0123456789012345678);
  EXPECT_EQ(child.source.faults, (std::vector<std::string>{"echoes=0.1", "beacon_dies=2@5"}));
  EXPECT_EQ(child.gateway.robot_id, "r7");
  EXPECT_EQ(child.gateway.duration_s, 12.345678901234567);
  EXPECT_EQ(child.gateway.speed, 2.5);
  EXPECT_EQ(child.seed, 18446744073709551615ULL);
  EXPECT_EQ(child.gateway.truth_csv, "/tmp/truth.csv");
  EXPECT_EQ(child.decoder.min_range_m, 0.1);
  EXPECT_EQ(child.decoder.max_range_m, parent.decoder.max_range_m);
  EXPECT_EQ(child.decoder.range_sigma_m, 0.0123456789);
  EXPECT_EQ(child.decoder.range_scale, 1.069);
  EXPECT_EQ(child.decoder.max_age_ns, 333'333'333);
  EXPECT_EQ(child.decoder.max_age_ns, parent.decoder.max_age_ns);
}

TEST(OptionSets, TheLocalizersSettingsReachItsChildBitForBit) {
  LocalizerSettings parent;
  {
    CLI::App app;
    localizer_option_set(parent, true).add_to(&app);
    std::vector<std::string> args{"beaconloc",   "--estimator",    "duhl",     "--receivers", "0.19:0,-0.095:0.16454482671904333",
                                  "--param",     "nis_gate=9.5",   "--param",  "init_window_s=4", "--initial-pose",
                                  "1.25",        "-2.5",           "0.30000000000000004", "--robot", "r9",
                                  "--receiver-height-m", "0.123456789012345678"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    app.parse(static_cast<int>(argv.size()), argv.data());
  }
  LocalizerSettings child;
  CLI::App app;
  localizer_option_set(child, true).add_to(&app);
  std::vector<std::string> args = localizer_option_set(parent, true).arguments();
  args.insert(args.begin(), "beaconloc");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  app.parse(static_cast<int>(argv.size()), argv.data());
  EXPECT_EQ(child.estimator, "duhl");
  EXPECT_EQ(child.receivers, parent.receivers);
  EXPECT_EQ(child.parameters, (std::vector<std::string>{"nis_gate=9.5", "init_window_s=4"}));
  EXPECT_EQ(child.initial_pose, (std::vector<double>{1.25, -2.5, 0.30000000000000004}));
  EXPECT_EQ(child.robot, "r9");
  EXPECT_EQ(child.receiver_height_m, parent.receiver_height_m);
  EXPECT_EQ(child.receiver_count, parent.receiver_count);
}

TEST(OptionSets, AnEmptyRobotIdIsAValueTheChildKeeps) {
  Settings parent;
  parent.parse({"--robot", ""});
  Settings child;
  child.parse(parent.arguments());
  EXPECT_EQ(child.gateway.robot_id, "");
}

TEST(OptionSets, WhatWasNotSetIsNotWrittenForTheChild) {
  Settings parent;
  parent.parse({});
  const std::vector<std::string> args = parent.arguments();
  for (const char* unset : {"--scenario", "--replay", "--fault", "--seed", "--truth-out", "--qos"}) {
    EXPECT_EQ(std::find(args.begin(), args.end(), unset), args.end()) << unset;
  }
  Settings child;
  child.parse(args);
  EXPECT_EQ(child.decoder.max_age_ns, TofDecoderConfig{}.max_age_ns);
  EXPECT_FALSE(child.seed.has_value());
  EXPECT_EQ(child.gateway.speed, GatewayOptions{}.speed);
}

}  // namespace
}  // namespace beaconloc::cli
