#include "offline_run.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "sim/sim_source.hpp"

namespace beaconloc {

namespace {

EstimatorConfig config_for(const sim::Scenario& scenario, const std::map<std::string, double>& parameters) {
  EstimatorConfig config;
  config.receivers = scenario.receivers;
  config.parameters = parameters;
  return config;
}

}  // namespace

std::vector<SourceEvent> simulate(const sim::Scenario& scenario, std::uint64_t seed, double duration_s) {
  sim::SimSource source(scenario, seed);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(duration_s), events);
  return events;
}

OfflineStack::OfflineStack(const sim::Scenario& scenario, const std::string& estimator,
                           const std::map<std::string, double>& parameters)
    : localizer(estimator, config_for(scenario, parameters)) {
  localizer.set_beacon_map(BeaconMap(scenario.beacons));
  decoder.set_beacon_map(BeaconMap(scenario.beacons));
}

std::optional<LocalizerOutput> OfflineStack::feed(const std::string& robot_id, const SourceEvent& e) {
  if (e.kind == SourceEvent::Kind::kTof) {
    if (const auto out = decoder.decode(robot_id, e.tof); out.range)
      localizer.on_range(robot_id, out.range->range);
    return std::nullopt;
  }
  if (e.kind != SourceEvent::Kind::kOdometry) return std::nullopt;
  return localizer.on_odometry(robot_id, e.odometry);
}

OfflineRunResult run_scenario_offline(const sim::Scenario& scenario, std::uint64_t seed,
                                      const std::string& estimator,
                                      const std::vector<std::string>& parameters, double settle_s) {
  OfflineStack stack(scenario, estimator, parse_estimator_parameters(parameters, "parameter"));
  TruthTrack truth;
  std::vector<EstimateRow> rows;
  for (const auto& e : simulate(scenario, seed, scenario.duration_s)) {
    if (e.kind == SourceEvent::Kind::kOdometry) truth.add(e.stamp_ns, e.truth_map_base);
    if (auto pose = stack.feed("robot", e)) rows.push_back({"robot", pose->estimate, estimator});
  }
  OfflineRunResult result;
  result.poses = rows.size();
  EvaluationOptions options;
  if (!rows.empty()) options.score_from_ns = rows.front().estimate.stamp_ns + s_to_ns(settle_s);
  result.metrics = evaluate(truth, rows, options);
  return result;
}

namespace {

std::string mean_and_spread(const std::vector<double>& values, int decimals) {
  if (values.empty()) return "n/a";
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= static_cast<double>(values.size());
  double var = 0.0;
  for (double v : values) var += (v - mean) * (v - mean);
  const double sd = values.size() > 1 ? std::sqrt(var / static_cast<double>(values.size() - 1)) : 0.0;
  char text[64];
  std::snprintf(text, sizeof text, "%.*f +- %.*f", decimals, mean, decimals, sd);
  return text;
}

}  // namespace

std::string accuracy_table_markdown(const std::vector<AccuracyRow>& rows) {
  std::ostringstream out;
  out << "| scenario | estimator | seeds | E_p RMS (m) | E_phi RMS (deg) | E_S mean (m) | NEES in band |\n"
      << "|---|---|---|---|---|---|---|\n";
  for (const auto& row : rows) {
    std::vector<double> ep, ephi, es, nees;
    for (const auto& m : row.runs) {
      ep.push_back(m.position_rms_m);
      if (m.heading_rms_deg) ephi.push_back(*m.heading_rms_deg);
      if (m.significant_points_mean_m) es.push_back(*m.significant_points_mean_m);
      nees.push_back(m.nees_in_band_fraction);
    }
    out << "| " << row.scenario << " | " << row.estimator << " | " << row.runs.size() << " | "
        << mean_and_spread(ep, 3) << " | " << mean_and_spread(ephi, 2) << " | " << mean_and_spread(es, 3)
        << " | " << mean_and_spread(nees, 2) << " |\n";
  }
  return out.str();
}

}  // namespace beaconloc
