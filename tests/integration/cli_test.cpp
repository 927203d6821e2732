// The beaconloc command line as a user meets it: help everywhere, a clear error naming a bad
// argument or configuration with a non-zero exit, a clean stop on signals, and the demo.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "beaconloc/dds/wall_clock.hpp"
#include "diagnostics_recorder.hpp"
#include "domain_id.hpp"
#include "participants_test.hpp"
#include "process.hpp"

namespace beaconloc::testing {
namespace {

using namespace std::chrono_literals;

std::pair<int, std::string> beaconloc(std::vector<std::string> args) {
  args.insert(args.begin(), BEACONLOC_EXECUTABLE);
  return run_command(args, 120s);
}

TEST(Cli, HelpEverywhere) {
  auto [code, out] = beaconloc({"--help"});
  EXPECT_EQ(code, 0);
  for (const char* sub : {"gateway", "decoder", "localizer", "demo", "run", "eval", "accuracy", "monitor"}) {
    EXPECT_NE(out.find(sub), std::string::npos) << sub;
    auto [sub_code, sub_out] = beaconloc({sub, "--help"});
    EXPECT_EQ(sub_code, 0) << sub;
    const std::string sub_name = sub;
    const char* expected = sub_name == "eval" ? "--truth" : sub_name == "accuracy" ? "--seeds" : "--domain";
    EXPECT_NE(sub_out.find(expected), std::string::npos) << sub;
  }
}

TEST(Cli, NoSubcommandIsAnError) {
  auto [code, out] = beaconloc({});
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("subcommand"), std::string::npos) << out;
}

struct BadInvocation {
  std::vector<std::string> args;
  std::string must_name;
};

TEST(Cli, BadArgumentsAndConfigurationNameTheCulpritAndFail) {
  const std::string bad_xml = "/tmp/beaconloc-cli-bad-qos.xml";
  std::ofstream(bad_xml) << "<dds><profiles><participant profile_name=\"x\"><rtps>\n";
  // Configuration files (cli/config_file.hpp): a key that is no option of its section's command,
  // and a value the option refuses, as on the command line.
  const std::string bad_config = "/tmp/beaconloc-cli-bad-config.yaml";
  std::ofstream(bad_config) << "localizer:\n  ros__parameters:\n    estimater: range_ekf\n";
  const std::string bad_value = "/tmp/beaconloc-cli-bad-value.yaml";
  std::ofstream(bad_value) << "/**:\n  ros__parameters:\n    domain: 999\n";
  const std::vector<BadInvocation> cases = {
      {{"gateway", "--speed", "-1"}, "--speed"},
      {{"gateway", "--speed", "fast"}, "--speed"},
      {{"gateway", "--duration-s", "-3"}, "--duration-s"},
      {{"gateway", "--replay", "/nonexistent/dir"}, "/nonexistent/dir"},
      {{"gateway", "--scenario", "/nonexistent.yaml"}, "/nonexistent.yaml"},
      {{"decoder", "--max-range-m", "0"}, "--max-range-m"},
      {{"localizer", "--domain", "999"}, "--domain"},
      {{"localizer", "--estimator", "nope"}, "nope"},
      {{"localizer", "--param", "nis_gate"}, "--param"},
      {{"localizer", "--param", "nis_gate=abc"}, "--param"},
      {{"localizer", "--qos", "/nonexistent/qos.xml"}, "/nonexistent/qos.xml"},
      {{"localizer", "--qos", bad_xml}, bad_xml},
      {{"decoder", "--participant-profile", "no.such.profile"}, "no.such.profile"},
      {{"gateway", "--no-such-flag"}, "--no-such-flag"},
      {{"decoder", "--config", bad_config}, "'localizer.estimater': localizer has no option --estimater"},
      {{"decoder", "--config", bad_value}, "--domain"},
      {{"decoder", "--keystore="}, "--keystore"},
      {{"localizer", "--estimator-plugin", bad_xml}, "estimator plugin " + bad_xml + ": cannot be loaded"},
  };
  for (const auto& c : cases) {
    auto [code, out] = beaconloc(c.args);
    std::string joined;
    for (const auto& a : c.args) joined += a + " ";
    EXPECT_NE(code, 0) << joined;
    EXPECT_NE(out.find(c.must_name), std::string::npos) << joined << "\n" << out;
  }
  std::remove(bad_xml.c_str());
  std::remove(bad_config.c_str());
  std::remove(bad_value.c_str());
}

// A mistyped or out-of-range --param stops every command that creates an estimator at start,
// naming the parameter (and the known ones, or the range), before any data flows.
TEST(Cli, EveryCommandRefusesABadEstimatorParameterAtStart) {
  DomainLease domain;
  const std::string scenario = std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/default.yaml";
  const std::string out = "/tmp/beaconloc-cli-param-" + std::to_string(domain.id());
  const std::vector<std::vector<std::string>> commands = {
      {"localizer", "--domain", std::to_string(domain.id())},
      {"run", "--domain", std::to_string(domain.id()), "--out", out},
      {"run", "--domain", std::to_string(domain.id()), "--out", out, "--processes", "--speed", "5"},
      {"demo", "--domain", std::to_string(domain.id())},
      {"accuracy", "--scenario", scenario, "--seeds", "1"},
  };
  for (auto args : commands) {
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    auto typo = args;
    typo.insert(typo.end(), {"--param", "nis_gat=3"});
    auto [code, text] = beaconloc(typo);
    EXPECT_EQ(code, 2) << joined << "\n" << text;
    EXPECT_NE(text.find("range_ekf: unknown parameter 'nis_gat' (known: nis_gate,"), std::string::npos)
        << joined << "\n"
        << text;
    EXPECT_EQ(text.find("poses:"), std::string::npos) << joined << ": ran anyway\n" << text;
    auto negative = args;
    negative.insert(negative.end(), {"--param", "nis_gate=-1"});
    auto [negative_code, negative_text] = beaconloc(negative);
    EXPECT_EQ(negative_code, 2) << joined << "\n" << negative_text;
    EXPECT_NE(negative_text.find("nis_gate=-1 is outside (0, 1000]"), std::string::npos) << joined << "\n"
                                                                                         << negative_text;
  }
  std::filesystem::remove_all(out);
}

// Every number of the command line, and of the files it names, is a decimal number within its
// range; the error names the option as typed, or the file, line and key (issue 23, items 3, 7
// and 13). Each of these ends before any participant joins a domain.
TEST(Cli, NumbersOfOptionsAndFilesAreRangeCheckedNamingTheCulprit) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("beaconloc-cli-numbers-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string qos = (dir / "loopback.xml").string();
  std::ofstream(qos) << "<?xml version=\"1.0\"?>\n<profiles xmlns=\"http://www.eprosima.com/XMLSchemas/"
                        "fastRTPS_Profiles\">\n  <participant profile_name=\"beaconloc.loopback\"><rtps/>"
                        "</participant>\n</profiles>\n";
  const std::string map = (dir / "map.yaml").string();
  std::ofstream(map) << "image: map.pgm\nresolution: 1e-300\norigin: [0, 0, 0]\n";
  std::ofstream(dir / "map.pgm") << "P2\n1 1\n255\n0\n";
  const std::string scenario = (dir / "twice.yaml").string();
  {  // the default scenario with a second range_sigma_m line after its own (line 25)
    std::ifstream in(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/default.yaml");
    std::ofstream out(scenario);
    for (std::string line; std::getline(in, line);) {
      out << line << '\n';
      if (line.rfind("  range_sigma_m:", 0) == 0) out << "  range_sigma_m: 0.5\n";
    }
  }
  DomainLease lease;  // the cases end before joining it; a lease all the same
  const std::string domain = std::to_string(lease.id());
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"decoder", "--max-age-ms", "1e300"}, "--max-age-ms: '1e300' is outside (0, 60000]"},
      {{"gateway", "--seed", "-1"}, "--seed: '-1' is outside [0, 18446744073709551615]"},
      {{"decoder", "--max-range-m", "0x1p1"}, "--max-range-m: '0x1p1' is not a decimal number"},
      {{"gateway", "--duration-s", "1e300"}, "--duration-s: '1e300' is outside [0, 1e+06]"},
      {{"localizer", "--receiver-count", "3.5"}, "--receiver-count: '3.5' is not a whole decimal number"},
      {{"localizer", "--initial-pose", "0", "0", "inf"}, "--initial-pose: 'inf' is not a decimal number"},
      {{"localizer", "--domain", domain, "--receivers", "0:1e300"},
       "--receivers 1e+300 is outside [-10, 10]"},
      {{"localizer", "--domain", domain, "--param", "nis_gate=0x1p1"},
       "--param 'nis_gate=0x1p1': the value '0x1p1' is not a decimal number"},
      {{"localizer", "--domain", domain, "--map", map},
       "map.yaml:2: resolution 1e-300 is outside [0.001, 10]"},
      {{"localizer", "--domain", domain, "--qos", qos},
       "loopback.xml':3: participant 'beaconloc.loopback' is already defined (built in, or by an earlier "
       "file)"},
      {{"gateway", "--domain", domain, "--scenario", scenario},
       "twice.yaml:26: 'beacon_system.range_sigma_m' is repeated (first at line 25)"},
      {{"accuracy", "--scenario", scenario, "--seeds", "0x10"},
       "--seeds: '0x10' is not a whole decimal number"},
  };
  for (const auto& [args, message] : cases) {
    auto [code, out] = beaconloc(args);
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    EXPECT_NE(code, 0) << joined;
    EXPECT_NE(out.find(message), std::string::npos) << joined << "\n" << out;
  }
  std::filesystem::remove_all(dir);
}

TEST(Cli, ParticipantsStopCleanlyOnSigintAndSigterm) {
  DomainLease domain;
  dds::DdsOptions dds;
  dds.domain_id = domain.id();
  DiagnosticsRecorder diagnostics(dds);
  for (int sig : {SIGINT, SIGTERM}) {
    for (const char* sub : {"decoder", "localizer"}) {
      const StampNs started_ns = dds::wall_clock_ns();
      ChildProcess p({BEACONLOC_EXECUTABLE, sub, "--domain", std::to_string(domain.id())},
                     "/tmp/beaconloc-cli-signal.log");
      // Signalled once it runs (its first report), however long its start-up took.
      const std::string name = std::string(sub) == "decoder" ? kDecoder : kRangeEkfLocalizer;
      const auto report = wait_for_diagnostics(
          diagnostics, name, [&](const msg::Diagnostics& d) { return d.stamp_ns() >= started_ns; });
      ASSERT_GE(report.stamp_ns(), started_ns) << sub << " never reported\n" << p.log();
      p.signal(sig);
      const auto code = p.wait(10s);
      ASSERT_TRUE(code) << sub << " ignored signal " << sig;
      EXPECT_EQ(*code, 0) << sub << " signal " << sig << "\n" << p.log();
    }
  }
  std::remove("/tmp/beaconloc-cli-signal.log");
}

TEST(Cli, AccuracyPrintsATableOverSeeds) {
  auto [code, out] = beaconloc({"accuracy", "--scenario",
                                std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/default.yaml",
                                "--estimator", "range_ekf", "--seeds", "3"});
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("| default | range_ekf | 3 | "), std::string::npos) << out;
  auto [bad_code, bad_out] = beaconloc(
      {"accuracy", "--scenario", std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/default.yaml",
       "--estimator", "nope"});
  EXPECT_EQ(bad_code, 2);
  EXPECT_NE(bad_out.find("nope"), std::string::npos) << bad_out;
}

// In real time, the demo's own pace: the demo's gateway is paced by the wall clock and never
// waits for the localizer (only `run` at its default speed does), so faster than real time on a
// busy machine it outran the localizer's odometry history and the accuracy measured the load.
TEST(Cli, DemoEndsWithThePositionRmsAgainstGroundTruth) {
  DomainLease domain;
  auto [code, out] = beaconloc({"demo", "--domain", std::to_string(domain.id()), "--duration-s", "12"});
  EXPECT_EQ(code, 0) << out;
  const auto at = out.rfind("position RMS ");
  ASSERT_NE(at, std::string::npos) << out;
  const double rms = std::stod(out.substr(at + 13));
  EXPECT_GT(rms, 0.0);
  EXPECT_LT(rms, 0.15) << out;
}

}  // namespace
}  // namespace beaconloc::testing
