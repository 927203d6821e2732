#pragma once
// The estimators the product registers (plugins/localizer/estimators/<name>/), without the test
// doubles a test binary registers beside them (named test_*): the ones a test that must hold
// for every estimator of a paper walks through.
#include <string>
#include <vector>

#include "beaconloc/core/estimator_registry.hpp"

namespace beaconloc {

inline std::vector<std::string> shipped_estimators() {
  std::vector<std::string> out;
  for (const std::string& name : EstimatorRegistry::instance().names()) {
    if (name.rfind("test_", 0) != 0) out.push_back(name);
  }
  return out;
}

}  // namespace beaconloc
