#pragma once
// Configuration files (docs/deployment.md): every command takes --config FILE, a YAML file laid
// out as ROS 2 parameter files are, one file for a robot's whole setup:
//   /**:                  # every command that has the option
//     ros__parameters:
//       domain: 7
//       robot: robot1
//   localizer:            # that command alone
//     ros__parameters:
//       estimator: range_ekf
//       param: [nis_gate=9.0]
// Keys are the commands' long option names without "--"; a scalar is the option's value, a
// sequence its values (a repeatable option given once per item, or a multi-value option's
// numbers), true or false a flag. An option given on the command line overrides the file's (the
// whole key: a --param on the command line replaces the file's list), and the file's settings that
// exclude it, with those that need them (`gateway --scenario` on a robot whose file names its
// serial line and baud rate). A "/**" setting goes to the commands that have the option and meet
// its needs (a beacons file for the bridge is not the simulated gateway's).
#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace beaconloc::cli {

class ConfigFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Adds --config FILE to every command of `app`.
void add_config_option(CLI::App& app);

// `args` (the command line without the program's name) with the configuration file's settings for
// its command appended, when it gives --config FILE; else `args` unchanged. Every section of the
// file is checked, not only the command's own, so that a typo fails whichever participant reads
// the file first. Throws ConfigFileError naming the file and the key: unreadable or not YAML, a
// top-level key that is neither a command nor "/**", a section that is not
// {ros__parameters: {...}}, a key no command has (under "/**") or its command has not, a value
// that is null, a map or a nested list, a flag's value that is not true or false.
std::vector<std::string> with_config_file(const CLI::App& app, const std::vector<std::string>& args);

}  // namespace beaconloc::cli
