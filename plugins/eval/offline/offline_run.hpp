#pragma once
// A scenario run without DDS: the simulated source fed straight into the decoder and localizer
// cores (the same code the participants run), every pose scored against the simulator's truth.
// For accuracy tables over many seeds: deterministic, and as fast as the estimator.
#include <cstdint>
#include <string>
#include <vector>

#include "beaconloc/core/estimator.hpp"
#include "evaluation.hpp"
#include "sim/scenario.hpp"

namespace beaconloc {

struct OfflineRunResult {
  Metrics metrics;
  std::size_t poses = 0;
};

// Scores poses from settle_s after the first one (the first global fix is not tracking).
OfflineRunResult run_scenario_offline(const sim::Scenario& scenario, std::uint64_t seed,
                                      const std::string& estimator,
                                      const std::vector<std::string>& parameters, double settle_s = 0.0);

struct AccuracyRow {
  std::string scenario;
  std::string estimator;
  std::vector<Metrics> runs;  // one per seed
};

// A markdown table: mean and standard deviation over the seeds of E_p RMS, E_phi RMS, E_S mean
// and the NEES-in-band fraction, one row per scenario and estimator.
std::string accuracy_table_markdown(const std::vector<AccuracyRow>& rows);

}  // namespace beaconloc
