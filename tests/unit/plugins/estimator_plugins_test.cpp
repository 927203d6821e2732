// Estimator plugins built as out-of-tree ones are (beaconloc_add_estimator_plugin), loaded at run
// time (localizer/estimator_plugins.hpp): the example plugin's estimator localizes the built-in
// scenario like the built-in ones; each bad plugin is refused, naming the file and why, and adds
// nothing.
#include "estimator_plugins.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "beaconloc/core/estimator_plugin.hpp"
#include "offline_pipeline.hpp"
#include "sim/scenario_yaml.hpp"

namespace beaconloc {
namespace {

namespace fs = std::filesystem;

// The message of the refusal of `paths`, or "" when they were loaded.
std::string refusal(const std::vector<std::string>& paths) {
  try {
    load_estimator_plugins(paths);
  } catch (const EstimatorPluginError& e) {
    return e.what();
  }
  return "";
}

fs::path scratch_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("beaconloc-plugins-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(EstimatorPlugins, TheExamplePluginsEstimatorLocalizesTheBuiltInScenario) {
  const std::vector<std::string> added = load_estimator_plugins({EXAMPLE_PLUGIN});
  ASSERT_EQ(added, std::vector<std::string>{"example_placed_ekf"});
  EXPECT_TRUE(load_estimator_plugins({EXAMPLE_PLUGIN}).empty());  // the same file: loaded once
  EXPECT_NE(EstimatorRegistry::instance().description("example_placed_ekf"), "");

  // The localizer's pipeline without DDS, placed at the scenario's start, against its truth: the
  // seed-000 world with 1 cm ranges. A filter that did not fuse the ranges would drift with the
  // odometry (decimetres over the loop); one that diverged would be far off.
  const sim::Scenario scenario =
      sim::load_scenario_file(std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios/default.yaml");
  const testing::OfflineRun run = testing::run_offline(scenario, 3, 30.0, "example_placed_ekf");
  ASSERT_GT(run.poses, 2500u);
  EXPECT_LT(run.error.position_rms_m(), 0.03);
  EXPECT_LT(run.error.heading_rms_deg(), 5.0);
  EXPECT_GT(run.localizer_counts.accepted(), 0u);
}

TEST(EstimatorPlugins, APluginOfAnotherSdkIsRefusedNamingBothVersions) {
  const std::string why = refusal({OLD_SDK_PLUGIN});
  EXPECT_NE(why.find(OLD_SDK_PLUGIN), std::string::npos) << why;
  EXPECT_NE(why.find("another SDK: 'beaconloc-sdk 0.0;"), std::string::npos) << why;
  EXPECT_NE(why.find(BEACONLOC_SDK_ABI), std::string::npos) << why;
  EXPECT_NE(why.find("rebuild it"), std::string::npos) << why;
}

TEST(EstimatorPlugins, EachOtherBadPluginIsRefusedWithItsReasonAndAddsNothing) {
  const std::vector<std::string> before = EstimatorRegistry::instance().names();
  EXPECT_NE(refusal({NOT_A_PLUGIN}).find("is not a beaconloc estimator plugin"), std::string::npos);
  EXPECT_NE(refusal({EMPTY_PLUGIN}).find("registers no estimator"), std::string::npos);
  const std::string duplicate = refusal({DUPLICATE_PLUGIN});
  EXPECT_NE(duplicate.find("registers estimator 'range_ekf', which this localizer has already"),
            std::string::npos)
      << duplicate;
  EXPECT_NE(refusal({"/nonexistent/plugin.so"}).find("cannot be read"), std::string::npos);

  const fs::path dir = scratch_dir("bad");
  {
    std::ofstream text(dir / "not_elf.so");
    text << "not a shared library\n";
  }
  const std::string not_elf = refusal({(dir / "not_elf.so").string()});
  EXPECT_NE(not_elf.find("cannot be loaded: "), std::string::npos) << not_elf;
  // A directory: its *.so files in name order, the first bad one refused by name.
  const std::string in_dir = refusal({dir.string()});
  EXPECT_NE(in_dir.find("not_elf.so"), std::string::npos) << in_dir;
  fs::remove(dir / "not_elf.so");
  EXPECT_NE(refusal({dir.string()}).find("is a directory without any *.so file"), std::string::npos);
  fs::remove_all(dir);
  EXPECT_EQ(EstimatorRegistry::instance().names(), before);
}

TEST(EstimatorPlugins, ADirectoryLoadsEveryPluginInIt) {
  const fs::path dir = scratch_dir("good");
  fs::copy_file(EXAMPLE_PLUGIN, dir / "libexample.so");
  {
    std::ofstream readme(dir / "README");  // not a *.so: not loaded
    readme << "plugins\n";
  }
  if (EstimatorRegistry::instance().factory("example_placed_ekf")) {
    // This process loaded the example from its own file already (the tests run in one process):
    // the copy is another file, whose estimator's name is taken.
    EXPECT_NE(refusal({dir.string()}).find("has already"), std::string::npos);
    fs::remove_all(dir);
    return;
  }
  EXPECT_EQ(load_estimator_plugins({dir.string()}), std::vector<std::string>{"example_placed_ekf"});
  // The same plugin from another file (a second copy): its name is taken now.
  fs::copy_file(EXAMPLE_PLUGIN, dir / "libexample_copy.so");
  EXPECT_NE(refusal({(dir / "libexample_copy.so").string()}).find("has already"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace beaconloc
