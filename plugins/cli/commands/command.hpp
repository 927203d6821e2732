#pragma once
// A beaconloc command (gateway, decoder, localizer, bridge, monitor, demo, run, eval, accuracy):
// it declares itself and its options on the command line when made, holds what they parse into,
// and runs once they are parsed. main.cpp only wires them (add_commands, then the parsed one).
#include <CLI/CLI.hpp>
#include <memory>
#include <vector>

namespace beaconloc::cli {

class Command {
 public:
  virtual ~Command() = default;
  Command(const Command&) = delete;
  Command& operator=(const Command&) = delete;

  bool parsed() const { return app_->parsed(); }
  // Whether it runs DDS participants: then a stop signal asks it to stop cleanly (its entities
  // and shared-memory files released). The offline commands hold no DDS entity: a signal keeps
  // its default action and ends them at once.
  virtual bool runs_participants() const { return true; }
  // The process's exit status. Throws on a bad setting or a failure (main prints it, exit 2).
  virtual int execute() = 0;

 protected:
  explicit Command(CLI::App* app) : app_(app) {}
  CLI::App* app_;
};

// Every command, declared on `app` in the order `beaconloc --help` lists them.
std::vector<std::unique_ptr<Command>> add_commands(CLI::App& app);

// The commands of each file (commands/*.cpp).
void add_participant_commands(CLI::App& app, std::vector<std::unique_ptr<Command>>& out);
void add_pipeline_commands(CLI::App& app, std::vector<std::unique_ptr<Command>>& out);
void add_offline_commands(CLI::App& app, std::vector<std::unique_ptr<Command>>& out);
void add_monitor_command(CLI::App& app, std::vector<std::unique_ptr<Command>>& out);
void add_record_command(CLI::App& app, std::vector<std::unique_ptr<Command>>& out);
void add_serial_sim_command(CLI::App& app, std::vector<std::unique_ptr<Command>>& out);

}  // namespace beaconloc::cli
