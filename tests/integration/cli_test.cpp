// The beaconloc command line as a user meets it: help everywhere, a clear error naming a bad
// argument or configuration with a non-zero exit, a clean stop on signals, and the demo.
#include <gtest/gtest.h>
#include <signal.h>

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
  const char* must_name;
};

TEST(Cli, BadArgumentsAndConfigurationNameTheCulpritAndFail) {
  const std::string bad_xml = "/tmp/beaconloc-cli-bad-qos.xml";
  std::ofstream(bad_xml) << "<dds><profiles><participant profile_name=\"x\"><rtps>\n";
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
      {{"localizer", "--qos", bad_xml}, bad_xml.c_str()},
      {{"decoder", "--participant-profile", "no.such.profile"}, "no.such.profile"},
      {{"gateway", "--no-such-flag"}, "--no-such-flag"},
  };
  for (const auto& c : cases) {
    auto [code, out] = beaconloc(c.args);
    std::string joined;
    for (const auto& a : c.args) joined += a + " ";
    EXPECT_NE(code, 0) << joined;
    EXPECT_NE(out.find(c.must_name), std::string::npos) << joined << "\n" << out;
  }
  std::remove(bad_xml.c_str());
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

TEST(Cli, DemoEndsWithThePositionRmsAgainstGroundTruth) {
  DomainLease domain;
  auto [code, out] =
      beaconloc({"demo", "--domain", std::to_string(domain.id()), "--duration-s", "12", "--speed", "4"});
  EXPECT_EQ(code, 0) << out;
  const auto at = out.rfind("position RMS ");
  ASSERT_NE(at, std::string::npos) << out;
  const double rms = std::stod(out.substr(at + 13));
  EXPECT_GT(rms, 0.0);
  EXPECT_LT(rms, 0.15) << out;
}

}  // namespace
}  // namespace beaconloc::testing
