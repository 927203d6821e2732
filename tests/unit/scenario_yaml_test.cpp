// Scenario files: every shipped file loads; the built-in default is default.yaml; a bad file
// gets an error naming the key and its line.
#include "sim/scenario_yaml.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "sim/sim_source.hpp"

namespace beaconloc::sim {
namespace {

const std::string kScenarioDir = std::string(BEACONLOC_SOURCE_DIR) + "/examples/scenarios";

TEST(ScenarioYaml, EveryShippedScenarioLoads) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kScenarioDir)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const Scenario s = load_scenario_file(entry.path().string());
    EXPECT_FALSE(s.beacons.empty());
    EXPECT_FALSE(s.receivers.receivers_base_m.empty());
    EXPECT_GT(s.duration_s, 0.0);
    ++loaded;
  }
  EXPECT_GE(loaded, 9);  // default + seed 000 x4 + seeds 001-004
}

TEST(ScenarioYaml, DefaultFileIsTheBuiltInScenario) {
  const Scenario file = load_scenario_file(kScenarioDir + "/default.yaml");
  SimSource a(file, 5), b(default_scenario(), 5);
  std::vector<SourceEvent> ea, eb;
  a.advance(s_to_ns(30.0), ea);
  b.advance(s_to_ns(30.0), eb);
  ASSERT_EQ(ea.size(), eb.size());
  for (std::size_t i = 0; i < ea.size(); ++i) {
    ASSERT_EQ(ea[i].stamp_ns, eb[i].stamp_ns);
    ASSERT_NEAR(ea[i].tof.tof_s, eb[i].tof.tof_s, 1e-12);
    ASSERT_TRUE(ea[i].truth_map_base.isApprox(eb[i].truth_map_base, 1e-6) ||
                (ea[i].truth_map_base - eb[i].truth_map_base).norm() < 1e-6);
  }
}

const char* kMinimal = R"(name: t
beacons:
  - {id: 1, position_m: [0, 0, 2]}
robot:
  receivers: {positions_m: [[0, 0]]}
trajectory:
  waypoints_m: [[0, 0], [1, 0]]
  speed_mps: 0.5
)";

std::string error_of(const std::string& yaml) {
  try {
    parse_scenario(yaml, "test.yaml");
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "";
}

TEST(ScenarioYaml, MinimalFileUsesTheDocumentedDefaults) {
  const Scenario s = parse_scenario(kMinimal);
  EXPECT_EQ(s.slot_period_ns, 200 * kNsPerMillisecond);
  EXPECT_DOUBLE_EQ(s.range_sigma_m, 0.01);
  EXPECT_TRUE(s.identified);
  EXPECT_TRUE(s.radio_sync);
  EXPECT_EQ(s.score_from_s, 0.0);
  EXPECT_EQ(s.firing_order, std::vector<std::uint32_t>{1});
  EXPECT_FALSE(s.map);
  EXPECT_NEAR(s.trajectory.period_s(), 2.0, 1e-12);
}

TEST(ScenarioYaml, UnmappedObstaclesAreInTheWorldTheLaserSeesNotInTheMap) {
  const Scenario s = parse_scenario(std::string(kMinimal) + R"(map:
  size_m: [4.0, 3.0]
  obstacles:
    - {min_m: [1.0, 1.0], max_m: [1.5, 1.5]}
  unmapped_obstacles:
    - {min_m: [2.5, 1.0], max_m: [3.0, 1.5]}
)");
  ASSERT_TRUE(s.map && s.world);
  EXPECT_TRUE(s.map->occupied_at({1.25, 1.25}) && s.world->occupied_at({1.25, 1.25}));
  EXPECT_FALSE(s.map->occupied_at({2.75, 1.25}));
  EXPECT_TRUE(s.world->occupied_at({2.75, 1.25}));
  EXPECT_FALSE(parse_scenario(kMinimal + std::string("map:\n  size_m: [4.0, 3.0]\n")).world);
}

TEST(ScenarioYaml, TheRoomAsBuiltIsOnAFinerGridThanTheMapWithPeopleAndTheScannersErrors) {
  const Scenario s = parse_scenario(std::string(kMinimal) + R"(map:
  resolution_m: 0.1
  world_resolution_m: 0.02
  size_m: [4.0, 3.0]
  border: false
  obstacles:
    - {min_m: [1.03, 1.0], max_m: [1.5, 1.5]}
  unmapped_obstacles:
    - {min_m: [2.5, 1.0], max_m: [2.53, 1.03]}
people:
  - {path_m: [[0.5, 0.5], [3.5, 0.5]], speed_mps: 0.8, radius_m: 0.25}
laser: {range_sigma_m: 0.006, systematic_error_m: 0.025, spot_diameter_at_window_m: 0.013,
        spot_divergence_rad: 0.011, echo_merge_m: 0.5}
)");
  ASSERT_TRUE(s.map && s.world && s.laser);
  EXPECT_DOUBLE_EQ(s.world->resolution_m(), 0.02);
  // A face at x = 1.03: the map's cell [1.0, 1.1) is occupied (its centre lies in the obstacle),
  // and so is the room's [1.02, 1.04): 2 cm apart where the laser meets them.
  EXPECT_NEAR(*s.map->cast_ray({0.5, 1.25}, 0.0, 10.0), 0.5, 1e-9);
  EXPECT_NEAR(*s.world->cast_ray({0.5, 1.25}, 0.0, 10.0), 0.52, 1e-9);
  EXPECT_TRUE(s.world->occupied_at({2.51, 1.01}));
  EXPECT_FALSE(s.map->occupied_at({2.51, 1.01}));
  ASSERT_EQ(s.people.size(), 1u);
  EXPECT_TRUE(s.people[0].at(2.5).centre_m.isApprox(Eigen::Vector2d(2.5, 0.5)));
  EXPECT_DOUBLE_EQ(s.laser->systematic_error_m, 0.025);
  EXPECT_DOUBLE_EQ(s.laser->spot.divergence_rad, 0.011);
  EXPECT_DOUBLE_EQ(s.laser->spot.echo_merge_m, 0.5);
  EXPECT_NE(error_of(std::string(kMinimal) + "people:\n  - {path_m: [[0, 0]]}\n")
                .find("'people[0].path_m' must list 2 to 1000 points"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "people:\n  - {path_m: [[1, 1], [1, 1]]}\n").find("finite length"),
            std::string::npos);
  std::string crowd = std::string(kMinimal) + "people:\n";
  for (int i = 0; i < 101; ++i) crowd += "  - {path_m: [[0, 0], [1, 1]]}\n";
  EXPECT_NE(error_of(crowd).find("'people' may list at most 100 walkers"), std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "map: {size_m: [4, 3], world_resolution_m: 0.5}\n")
                .find("'map.world_resolution_m' must be in"),
            std::string::npos);
}

TEST(ScenarioYaml, ErrorsNameTheKeyAndLine) {
  EXPECT_EQ(error_of(std::string(kMinimal) + "colour: red\n"), "test.yaml:9: 'colour' is not a known key");
  EXPECT_NE(error_of(std::string(kMinimal) + "beacon_system: {range_sigma_m: -1}\n")
                .find("'beacon_system.range_sigma_m' must be in"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "beacon_system: {identified: maybe}\n")
                .find("'beacon_system.identified' has the wrong type"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "beacon_system: {firing_order: [7]}\n").find("names beacon 7"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "beacon_system: {group_coverage_radius_m: 0}\n")
                .find("'beacon_system.group_coverage_radius_m' must be above 0"),
            std::string::npos);
  // A pulse without a radio message carries no id either.
  EXPECT_NE(error_of(std::string(kMinimal) + "beacon_system: {radio_sync: false}\n")
                .find("'beacon_system.radio_sync' false needs identified: false"),
            std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "score_from_s: -1\n").find("'score_from_s' must be in"), std::string::npos);
  EXPECT_NE(error_of("name: t\n").find("'beacons' is required"), std::string::npos);
  EXPECT_NE(error_of(std::string(kMinimal) + "laser: {beams: 3}\n").find("needs a map"), std::string::npos);
  EXPECT_NE(error_of("name: [unclosed\n").find("not valid YAML"), std::string::npos);
  std::string dup = kMinimal;
  dup.insert(dup.find("robot:"), "  - {id: 1, position_m: [1, 0, 2]}\n");
  EXPECT_NE(error_of(dup).find("repeats an earlier beacon id"), std::string::npos);
  EXPECT_NE(error_of("name: t\nbeacons: []\n").find("at least one beacon"), std::string::npos);
  try {
    load_scenario_file("/nonexistent.yaml");
    FAIL();
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent.yaml"), std::string::npos);
  }
}

// A scenario with two range_sigma_m lines gave no pose and no hint why (the first silently won):
// a key given twice, at any depth, is an error naming it and both lines.
TEST(ScenarioYaml, AKeyGivenTwiceIsAnErrorNamingItAndItsLines) {
  EXPECT_EQ(error_of(std::string(kMinimal) +
                     "beacon_system:\n  range_sigma_m: 0.01\n  max_range_m: 5\n  range_sigma_m: 0.5\n"),
            "test.yaml:12: 'beacon_system.range_sigma_m' is repeated (first at line 10)");
  EXPECT_EQ(error_of(std::string(kMinimal) + "name: u\n"),
            "test.yaml:9: 'name' is repeated (first at line 1)");
  std::string nested = kMinimal;
  nested.replace(nested.find("[0, 0, 2]}"), 10, "[0, 0, 2], id: 2}");
  EXPECT_EQ(error_of(nested), "test.yaml:3: 'beacons[0].id' is repeated (first at line 3)");
}

// Every number of a scenario is decimal (core/decimal.hpp) and whole where it counts things.
TEST(ScenarioYaml, NumbersAreDecimalAndCountsWhole) {
  EXPECT_EQ(error_of(std::string(kMinimal) + "beacon_system: {range_sigma_m: 0x1p1}\n"),
            "test.yaml:9: 'beacon_system.range_sigma_m' is not a decimal number ('0x1p1')");
  EXPECT_EQ(error_of(std::string(kMinimal) + "beacon_system: {range_sigma_m: .inf}\n"),
            "test.yaml:9: 'beacon_system.range_sigma_m' is not a decimal number ('.inf')");
  EXPECT_EQ(error_of(std::string(kMinimal) + "duration_s: 1e400\n"),
            "test.yaml:9: 'duration_s' is out of range ('1e400')");
  EXPECT_EQ(error_of(std::string(kMinimal) + "seed: -1\n"), "test.yaml:9: 'seed' is out of range ('-1')");
  std::string circle = kMinimal;
  circle.replace(circle.find("{positions_m: [[0, 0]]}"), 23, "{circle: {radius_m: 0.2, count: 3.5}}");
  EXPECT_EQ(error_of(circle), "test.yaml:5: 'robot.receivers.circle.count' is not a decimal number ('3.5')");
  std::string far = kMinimal;
  far.replace(far.find("[[0, 0]]"), 8, "[[0, 1e300]]");
  EXPECT_EQ(error_of(far),
            "test.yaml:5: 'robot.receivers.positions_m[0][1]' must be in [-10, 10], got 1e+300");
  std::string octal = kMinimal;
  octal.replace(octal.find("id: 1"), 5, "id: 010");
  EXPECT_EQ(parse_scenario(octal).beacons.front().id, 10u);  // decimal, not octal
}

}  // namespace
}  // namespace beaconloc::sim
