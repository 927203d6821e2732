// Configuration files (cli/config_file.hpp): a ROS 2 parameter file's settings become the
// command's options, the command line overrides them, and every kind of mistake is refused naming
// the file and the key.
#include "config_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>

namespace beaconloc::cli {
namespace {

// Two commands with the kinds of options the real ones have.
struct Commands {
  CLI::App app{"test"};
  int domain = 0;
  std::string estimator = "range_ekf";
  std::vector<std::string> params;
  std::vector<double> initial_pose;
  bool odom_in = false;
  double max_range_m = 10.0;
  std::string robot;

  Commands() {
    CLI::App* localizer = app.add_subcommand("localizer");
    localizer->add_option("--domain", domain);
    localizer->add_option("--estimator", estimator);
    localizer->add_option("--param", params);
    localizer->add_option("--initial-pose", initial_pose)->expected(3);
    localizer->add_option("--robot", robot);
    localizer->add_flag("--odom-in", odom_in);
    CLI::App* decoder = app.add_subcommand("decoder");
    decoder->add_option("--domain", domain);
    decoder->add_option("--max-range-m", max_range_m);
    // The gateway's constraints between options: a serial line or a scenario, the line's settings
    // only with the line.
    CLI::App* gateway = app.add_subcommand("gateway");
    CLI::Option* scenario_option = gateway->add_option("--scenario", scenario);
    CLI::Option* serial_option = gateway->add_option("--serial", serial);
    serial_option->excludes(scenario_option);
    gateway->add_option("--baud", baud)->needs(serial_option);
    gateway->add_option("--beacons", beacons)->needs(serial_option);
    add_config_option(app);
  }
  std::string scenario;
  std::string serial;
  int baud = 0;
  std::string beacons;
  // Parses `args` with the file's settings; the error message, or "".
  std::string parse(const std::vector<std::string>& args) {
    try {
      std::vector<std::string> all = with_config_file(app, args);
      std::reverse(all.begin(), all.end());
      app.parse(all);
    } catch (const ConfigFileError& e) {
      return e.what();
    } catch (const CLI::ParseError& e) {
      return e.what();
    }
    return "";
  }
};

// The configuration files a test writes, removed when the test program ends.
struct ScratchFiles {
  std::vector<std::string> paths;
  ~ScratchFiles() {
    for (const std::string& path : paths) std::remove(path.c_str());
  }
};
ScratchFiles scratch_files;

std::string config_file(const std::string& name, const std::string& yaml) {
  const std::string path =
      ::testing::TempDir() + "/beaconloc-config-" + std::to_string(::getpid()) + "-" + name + ".yaml";
  std::ofstream(path) << yaml;
  scratch_files.paths.push_back(path);
  return path;
}

const char* const kRobotFile = R"(# one robot's setup
/**:
  ros__parameters:
    domain: 7
    robot: robot1
localizer:
  ros__parameters:
    estimator: example_placed_ekf
    param: [nis_gate=16, initial_sigma_xy_m=0.1]
    initial-pose: [-1.5, 0.25, -3.0]
    odom-in: true
    domain: 8
decoder:
  ros__parameters:
    max-range-m: 6.5
)";

TEST(ConfigFile, GivesTheCommandsOptionsItsOwnSectionOverEveryCommands) {
  const std::string path = config_file("robot", kRobotFile);
  Commands localizer;
  ASSERT_EQ(localizer.parse({"localizer", "--config", path}), "");
  EXPECT_EQ(localizer.domain, 8);  // its own section over "/**"
  EXPECT_EQ(localizer.robot, "robot1");
  EXPECT_EQ(localizer.estimator, "example_placed_ekf");
  EXPECT_EQ(localizer.params, (std::vector<std::string>{"nis_gate=16", "initial_sigma_xy_m=0.1"}));
  EXPECT_EQ(localizer.initial_pose, (std::vector<double>{-1.5, 0.25, -3.0}));  // negative numbers too
  EXPECT_TRUE(localizer.odom_in);

  Commands decoder;  // "/**" gives it the domain; the robot is no option of it
  ASSERT_EQ(decoder.parse({"decoder", "--config=" + path}), "");
  EXPECT_EQ(decoder.domain, 7);
  EXPECT_EQ(decoder.max_range_m, 6.5);
  EXPECT_EQ(decoder.estimator, "range_ekf");
}

TEST(ConfigFile, TheCommandLineOverridesTheFileKeyByKey) {
  const std::string path = config_file("robot", kRobotFile);
  Commands c;
  ASSERT_EQ(c.parse({"localizer", "--param", "nis_gate=4", "--config", path, "--domain=9"}), "");
  EXPECT_EQ(c.domain, 9);
  EXPECT_EQ(c.params, std::vector<std::string>{"nis_gate=4"});  // the whole list replaced
  EXPECT_EQ(c.estimator, "example_placed_ekf");
  Commands without;  // no --config: nothing read
  ASSERT_EQ(without.parse({"localizer", "--domain", "3"}), "");
  EXPECT_EQ(without.estimator, "range_ekf");
}

// A robot's file names its serial line; the command line simulates instead: the line's settings
// give way to the option that excludes them, and so do the ones that need it. A "/**" setting
// applies to the commands whose constraints it meets (the bridge's beacons, not a simulated
// gateway's); one of the command's own section whose needs the file lacks is refused by CLI11.
TEST(ConfigFile, TheCommandLineOverridesWhatExcludesItsOptionsAndWhatNeedsThose) {
  const std::string path = config_file("serial", R"(
/**:
  ros__parameters:
    beacons: site.csv
gateway:
  ros__parameters:
    serial: /dev/ttyUSB0
    baud: 115200
)");
  Commands simulated;
  ASSERT_EQ(simulated.parse({"gateway", "--config", path, "--scenario", "corridor.yaml"}), "");
  EXPECT_EQ(simulated.scenario, "corridor.yaml");
  EXPECT_EQ(simulated.serial, "");
  EXPECT_EQ(simulated.baud, 0);
  EXPECT_EQ(simulated.beacons, "");
  Commands live;
  ASSERT_EQ(live.parse({"gateway", "--config", path}), "");
  EXPECT_EQ(live.serial, "/dev/ttyUSB0");
  EXPECT_EQ(live.baud, 115200);
  EXPECT_EQ(live.beacons, "site.csv");

  const std::string lacking = config_file("lacking", "gateway:\n  ros__parameters:\n    baud: 9600\n");
  Commands refused;
  EXPECT_NE(refused.parse({"gateway", "--config", lacking}).find("--baud requires --serial"),
            std::string::npos);
}

TEST(ConfigFile, AnUnknownKeyIsRefusedNamingItWhicheverCommandReadsTheFile) {
  const std::string path = config_file("typo", R"(
localizer:
  ros__parameters:
    estimator: range_ekf
decoder:
  ros__parameters:
    max-range: 6.5
)");
  Commands c;
  const std::string why = c.parse({"localizer", "--config", path});
  EXPECT_NE(why.find(path + ": 'decoder.max-range': decoder has no option --max-range"), std::string::npos)
      << why;
}

TEST(ConfigFile, EveryOtherMistakeIsRefusedNamingTheFileAndWhere) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/**:\n  ros__parameters:\n    nonsense: 1\n", "'/**.nonsense': no command has an option --nonsense"},
      {"planner:\n  ros__parameters:\n    domain: 1\n",
       "'planner' is neither a command of beaconloc nor '/**'"},
      {"localizer:\n  domain: 1\n", "'localizer' must hold exactly 'ros__parameters:'"},
      {"localizer:\n  ros__parameters: [1, 2]\n", "must be a map of option names to values"},
      {"localizer:\n  ros__parameters:\n    odom-in: yes\n", "'localizer.odom-in' is a flag: true or false"},
      {"localizer:\n  ros__parameters:\n    domain: {a: 1}\n",
       "'localizer.domain' must be a value or a list"},
      {"localizer:\n  ros__parameters:\n    domain:\n", "'localizer.domain' must be a value or a list"},
      {"localizer:\n  ros__parameters:\n    param: [[a=1]]\n", "'localizer.param[0]' must be a single value"},
      {"localizer:\n  ros__parameters:\n    config: other.yaml\n", "localizer has no option --config"},
      {"localizer:\n  ros__parameters:\n    domain: 1\n    domain: 2\n", "is repeated"},
      {"- localizer\n", "must be a map of command names"},
      {"localizer: [\n", "not valid YAML"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string path = config_file("bad" + std::to_string(i), cases[i].first);
    Commands c;
    const std::string why = c.parse({"localizer", "--config", path});
    EXPECT_NE(why.find(path), std::string::npos) << cases[i].first << " -> " << why;
    EXPECT_NE(why.find(cases[i].second), std::string::npos) << cases[i].first << " -> " << why;
  }
  Commands missing;
  EXPECT_NE(missing.parse({"localizer", "--config", "/nonexistent.yaml"}).find("cannot be read"),
            std::string::npos);
}

}  // namespace
}  // namespace beaconloc::cli
