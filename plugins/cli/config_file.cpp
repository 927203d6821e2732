#include "config_file.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "beaconloc/core/yaml_document.hpp"

namespace beaconloc::cli {
namespace {

constexpr const char* kConfigFlag = "--config";
constexpr const char* kEveryCommand = "/**";               // ROS 2's wildcard: every node
constexpr const char* kParametersKey = "ros__parameters";  // as in a ROS 2 parameter file
constexpr std::size_t kMaxConfigBytes = 1 << 20;           // a robot's setup is a few hundred bytes

std::vector<const CLI::App*> commands_of(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App*) { return true; });
}

const CLI::App* command_named(const CLI::App& app, const std::string& name) {
  for (const CLI::App* command : commands_of(app)) {
    if (command->get_name() == name) return command;
  }
  return nullptr;
}

// The option `--key` of `command`, or null; never --config or --help (not settings).
const CLI::Option* option_of(const CLI::App& command, const std::string& key) {
  if (key == "config" || key == "help") return nullptr;
  return command.get_option_no_throw("--" + key);
}

// Whether the command line gives --flag (as "--flag" or "--flag=...").
bool given(const std::vector<std::string>& args, const std::string& flag) {
  return std::any_of(args.begin(), args.end(),
                     [&](const std::string& a) { return a == flag || a.rfind(flag + "=", 0) == 0; });
}

class ConfigFile {
 public:
  explicit ConfigFile(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const { throw ConfigFileError(path_ + ": " + what); }

  YAML::Node load() const {
    std::ifstream in(path_, std::ios::binary);
    if (!in) fail("cannot be read");
    std::string text(kMaxConfigBytes + 1, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxConfigBytes) fail("larger than " + std::to_string(kMaxConfigBytes) + " bytes");
    try {
      return load_yaml(text, path_);
    } catch (const YamlError& e) {
      throw ConfigFileError(e.what());  // names the file and the line
    }
  }

  // The {key: value} of a section ("<command>: {ros__parameters: {...}}").
  YAML::Node parameters(const YAML::Node& section, const std::string& name) const {
    if (!section.IsMap() || section.size() != 1 || !section[kParametersKey]) {
      fail("'" + name + "' must hold exactly '" + kParametersKey + ":' (the ROS 2 parameter file layout)");
    }
    const YAML::Node parameters = section[kParametersKey];
    if (parameters.IsNull()) return YAML::Node(YAML::NodeType::Map);
    if (!parameters.IsMap())
      fail("'" + name + "." + kParametersKey + "' must be a map of option names to values");
    return parameters;
  }

  // The arguments that give `value` to `option` ("--key" for a flag set true, none for false).
  std::vector<std::string> arguments(const CLI::Option& option, const std::string& where,
                                     const YAML::Node& value) const {
    const std::string flag = option.get_name();
    if (option.get_expected_max() == 0) {  // a flag: takes no value
      if (!value.IsScalar() || (value.Scalar() != "true" && value.Scalar() != "false")) {
        fail("'" + where + "' is a flag: true or false");
      }
      return value.Scalar() == "true" ? std::vector<std::string>{flag} : std::vector<std::string>{};
    }
    if (value.IsScalar()) return {flag + "=" + value.Scalar()};
    if (!value.IsSequence() || value.size() == 0) {
      fail("'" + where + "' must be a value or a list of values");
    }
    std::vector<std::string> out;
    const bool one_value_each = option.get_expected_max() <= 1 || option.get_type_size_max() > 1;
    if (!one_value_each) out.push_back(flag);
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (!value[i].IsScalar()) fail("'" + where + "[" + std::to_string(i) + "]' must be a single value");
      if (one_value_each) {
        out.push_back(flag + "=" + value[i].Scalar());
      } else {
        out.push_back(value[i].Scalar());
      }
    }
    return out;
  }

 private:
  std::string path_;
};

// The --config FILE of `args`, or empty.
std::string config_path(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == kConfigFlag && i + 1 < args.size()) return args[i + 1];
    if (args[i].rfind(std::string(kConfigFlag) + "=", 0) == 0)
      return args[i].substr(std::string(kConfigFlag).size() + 1);
  }
  return {};
}

}  // namespace

void add_config_option(CLI::App& app) {
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) {
    // Bound to nothing: the file is read before parsing (with_config_file), not after.
    command->add_option(kConfigFlag)
        ->description("read settings from this YAML file (ROS 2 parameter file layout: '/**' or '" +
                      command->get_name() +
                      "', then ros__parameters: option names without --); options given here override it")
        ->check(CLI::ExistingFile);
  }
}

std::vector<std::string> with_config_file(const CLI::App& app, const std::vector<std::string>& args) {
  const auto chosen = std::find_if(args.begin(), args.end(),
                                   [&](const std::string& a) { return command_named(app, a) != nullptr; });
  if (chosen == args.end()) return args;
  const CLI::App& command = *command_named(app, *chosen);
  const std::vector<std::string> command_args(chosen + 1, args.end());
  const std::string path = config_path(command_args);
  if (path.empty()) return args;

  const ConfigFile file(path);
  const YAML::Node root = file.load();
  if (root.IsNull()) return args;  // an empty file sets nothing
  if (!root.IsMap()) file.fail("must be a map of command names (or '/**') to their settings");

  YAML::Node every;
  YAML::Node own;
  for (const auto& section : root) {
    const std::string name = section.first.Scalar();
    const YAML::Node parameters = file.parameters(section.second, name);
    if (name == kEveryCommand) {
      for (const auto& item : parameters) {
        const std::string key = item.first.Scalar();
        const auto commands = commands_of(app);
        if (std::none_of(commands.begin(), commands.end(),
                         [&](const CLI::App* c) { return option_of(*c, key) != nullptr; })) {
          file.fail("'" + name + "." + key + "': no command has an option --" + key);
        }
      }
      every = parameters;
      continue;
    }
    const CLI::App* section_command = command_named(app, name);
    if (!section_command) file.fail("'" + name + "' is neither a command of beaconloc nor '/**'");
    for (const auto& item : parameters) {
      const std::string key = item.first.Scalar();
      if (!option_of(*section_command, key)) {
        file.fail("'" + name + "." + key + "': " + name + " has no option --" + key);
      }
    }
    if (section_command == &command) own = parameters;
  }
  // The command's settings: "/**"'s, then its own section's, which override them key by key.
  struct Setting {
    const CLI::Option* option;
    std::string where;  // section.key, for the messages
    YAML::Node value;
    bool for_every_command;  // from "/**"
  };
  std::vector<Setting> settings;
  const auto take = [&](const YAML::Node& parameters, const std::string& section) {
    for (const auto& item : parameters) {
      const std::string key = item.first.Scalar();
      const CLI::Option* option = option_of(command, key);
      if (!option) continue;  // "/**" sets it for the commands that have it
      Setting setting{option, section + "." + key, item.second, section == kEveryCommand};
      const auto same =
          std::find_if(settings.begin(), settings.end(), [&](const Setting& s) { return s.option == option; });
      if (same == settings.end()) {
        settings.push_back(setting);
      } else {
        *same = setting;
      }
    }
  };
  if (every) take(every, kEveryCommand);
  if (own) take(own, command.get_name());

  // The command line overrides the file: a setting it gives itself, and one that excludes an
  // option it gives (a robot's file names its serial line; `gateway --scenario` simulates instead).
  const auto on_command_line = [&](const CLI::Option* o) { return given(command_args, o->get_name()); };
  const auto excluded_by_command_line = [&](const CLI::Option* option) {
    const std::vector<const CLI::Option*> options = command.get_options();
    return std::any_of(options.begin(), options.end(), [&](const CLI::Option* other) {
      return on_command_line(other) && (option->get_excludes().count(const_cast<CLI::Option*>(other)) > 0 ||
                                        other->get_excludes().count(const_cast<CLI::Option*>(option)) > 0);
    });
  };
  std::set<const CLI::Option*> overridden;
  for (const Setting& s : settings) {
    if (on_command_line(s.option) || excluded_by_command_line(s.option)) overridden.insert(s.option);
  }
  // Then a setting that needs one of those (the serial line's baud rate), and one of "/**" whose
  // needs this command lacks (the bridge's beacons file, which the gateway takes only with
  // --serial): it is for the commands it applies to. A setting of the command's own section whose
  // needs the file does not meet is kept, for CLI11 to refuse ("--baud requires --serial").
  const auto kept = [&](const CLI::Option* o) {
    return on_command_line(o) || std::any_of(settings.begin(), settings.end(), [&](const Setting& s) {
             return s.option == o && overridden.count(o) == 0;
           });
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (const Setting& s : settings) {
      if (overridden.count(s.option)) continue;
      for (const CLI::Option* need : s.option->get_needs()) {
        if (kept(need)) continue;
        if (overridden.count(need) || s.for_every_command) {
          overridden.insert(s.option);
          changed = true;
          break;
        }
      }
    }
  }

  // Before a "--" that ends the options, if there is one.
  std::vector<std::string> out = args;
  auto at = std::find(out.begin() + (chosen - args.begin()) + 1, out.end(), "--");
  for (const Setting& s : settings) {
    if (overridden.count(s.option)) continue;
    const std::vector<std::string> more = file.arguments(*s.option, s.where, s.value);
    at = out.insert(at, more.begin(), more.end()) + static_cast<std::ptrdiff_t>(more.size());
  }
  return out;
}

}  // namespace beaconloc::cli
