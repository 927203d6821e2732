// beaconloc: one executable, one command per participant (gateway, decoder, localizer, bridge),
// the whole pipeline on a source (demo, run), scoring (eval, accuracy) and a monitor. Each
// command is a class of commands/ that declares its options and runs; this only wires them, with
// the configuration file (--config) read first.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>

#include "beaconloc/core/sdk_version.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "commands/command.hpp"
#include "config_file.hpp"

namespace beaconloc::cli {

std::vector<std::unique_ptr<Command>> add_commands(CLI::App& app) {
  std::vector<std::unique_ptr<Command>> commands;
  add_participant_commands(app, commands);
  add_pipeline_commands(app, commands);
  add_offline_commands(app, commands);
  add_monitor_command(app, commands);
  add_record_command(app, commands);
  add_serial_sim_command(app, commands);
  return commands;
}

int run(int argc, char** argv) {
  CLI::App app{"beaconloc: localization of robots against ultrasonic ceiling beacons, over Fast DDS"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "beaconloc " BEACONLOC_SDK_VERSION);
  const std::vector<std::unique_ptr<Command>> commands = add_commands(app);
  add_config_option(app);
  // The configuration file's settings, as the options they are (config_file.hpp), then parsed.
  std::vector<std::string> args;
  try {
    args = with_config_file(app, std::vector<std::string>(argv + 1, argv + argc));
  } catch (const ConfigFileError& e) {
    std::cerr << "beaconloc: error: " << e.what() << '\n';
    return 2;
  }
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (const auto& command : commands) {
    if (!command->parsed()) continue;
    if (command->runs_participants()) dds::install_stop_handlers();
    try {
      return command->execute();
    } catch (const std::exception& e) {
      std::cerr << "beaconloc: error: " << e.what() << '\n';
      return 2;
    }
  }
  return 0;
}

}  // namespace beaconloc::cli

int main(int argc, char** argv) { return beaconloc::cli::run(argc, argv); }
