#pragma once
// Loads a scenario from YAML (schema: examples/scenarios/README.md). Strict: an unknown key, a
// key given twice, a missing required key, a wrong type, a number that is not decimal
// (core/decimal.hpp) or an out-of-range value is a ScenarioError naming the file, the key and
// its line (core/yaml_document.hpp loads the file).
#include <stdexcept>
#include <string>

#include "beaconloc/core/measurements.hpp"
#include "scenario.hpp"

namespace beaconloc::sim {

class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

Scenario load_scenario_file(const std::string& path);
Scenario parse_scenario(const std::string& yaml_text, const std::string& origin = "<string>");

}  // namespace beaconloc::sim
