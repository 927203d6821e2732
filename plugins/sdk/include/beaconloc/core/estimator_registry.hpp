#pragma once
// Estimators register themselves by name; the localizer creates them with --estimator NAME.
// Each paper adds a folder under plugins/localizer/estimators/ with a registration, never a
// branch in a switch.
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"

namespace beaconloc {

using EstimatorFactory = std::function<std::unique_ptr<Estimator>(const EstimatorConfig&)>;

class UnknownEstimator : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class EstimatorRegistry {
 public:
  static EstimatorRegistry& instance();
  // reference_scenario: a file of examples/scenarios/ the estimator is meant for (its paper's
  // setup), on which the suites that walk every estimator run it (tests/accuracy/
  // every_estimator_test.cpp, benchmarks/every_estimator_benchmark.cpp); empty for test doubles.
  bool add(const std::string& name, const std::string& description, const std::string& reference_scenario,
           EstimatorFactory factory);
  // Throws UnknownEstimator naming the known estimators.
  std::unique_ptr<Estimator> create(const std::string& name, const EstimatorConfig& config) const;
  std::vector<std::string> names() const;
  std::string description(const std::string& name) const;
  std::string reference_scenario(const std::string& name) const;
  // The factory registered under `name`; empty when none is (estimator_plugins: a plugin's
  // estimators are added to the localizer's registry through it).
  EstimatorFactory factory(const std::string& name) const;

 private:
  struct Entry {
    std::string description;
    std::string reference_scenario;
    EstimatorFactory factory;
  };
  std::map<std::string, Entry> entries_;
};

}  // namespace beaconloc

#define BEACONLOC_CONCAT_INNER(a, b) a##b
#define BEACONLOC_CONCAT(a, b) BEACONLOC_CONCAT_INNER(a, b)
// Use once per estimator at namespace scope in its .cpp.
#define BEACONLOC_REGISTER_ESTIMATOR(name, description, reference_scenario, factory) \
  static const bool BEACONLOC_CONCAT(beaconloc_registered_, __LINE__) =              \
      ::beaconloc::EstimatorRegistry::instance().add(name, description, reference_scenario, factory)
