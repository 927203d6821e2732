#pragma once
// The option groups of the beaconloc commands, each defined once (option_set.hpp): the commands
// (commands/*.cpp) add them, `run --processes` writes them back as its children's command lines.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "option_set.hpp"
#include "pipeline.hpp"

namespace beaconloc::cli {

// --domain, --participant-profile, --qos, --keystore, --enclave
OptionSet dds_option_set(dds::DdsOptions& o);
// --scenario, --replay (exclusive), --replay-wheel-base-m, --replay-odometry-k-v, --fault
OptionSet source_option_set(SourceChoice& s);
// --robot, --duration-s, --speed, --seed (nullopt: the scenario's), --truth-out
OptionSet gateway_option_set(GatewayOptions& o, std::optional<std::uint64_t>& seed);
// --min-range-m, --max-range-m, --range-sigma-m, --range-scale, --max-age-ms (max_age_ns is set
// from max_age_ms after parsing: decoder_config_with_age)
OptionSet decoder_option_set(TofDecoderConfig& o, double& max_age_ms);
// --estimator-plugin (localizer/estimator_plugins.hpp): in localizer_option_set, and alone for the
// commands that make estimators without DDS (accuracy)
OptionSet estimator_plugin_option_set(std::vector<std::string>& plugins);
// --estimator, --estimator-plugin, --receivers, --param, --map, --initial-pose; standalone (the localizer command,
// not demo or run, whose source gives the receivers and names the robot): also --robot,
// --receiver-radius-m, --receiver-count, --receiver-height-m.
OptionSet localizer_option_set(LocalizerSettings& o, bool standalone);
TofDecoderConfig decoder_config_with_age(TofDecoderConfig o, double max_age_ms);
double max_age_ms_of(const TofDecoderConfig& o);

}  // namespace beaconloc::cli
