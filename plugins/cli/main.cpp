// beaconloc: one executable, one command per participant (gateway, decoder, localizer, bridge),
// the whole pipeline on a source (demo, run), scoring (eval, accuracy) and a monitor. Each
// command is a class of commands/ that declares its options and runs; this only wires them.
#include <CLI/CLI.hpp>
#include <iostream>

#include "beaconloc/dds/stop_signal.hpp"
#include "commands/command.hpp"

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
  app.set_version_flag("--version", "beaconloc 0.1.0");
  const std::vector<std::unique_ptr<Command>> commands = add_commands(app);
  CLI11_PARSE(app, argc, argv);
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
