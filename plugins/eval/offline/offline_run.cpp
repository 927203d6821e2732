#include "offline_run.hpp"

#include <algorithm>
#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <cstdio>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "firing_scheduler.hpp"
#include "sim/sim_source.hpp"

namespace beaconloc {

EstimatorConfig estimator_config_for(const sim::Scenario& scenario, const std::map<std::string, double>& parameters,
                                     const std::optional<Pose2>& initial_pose) {
  EstimatorConfig config;
  config.receivers = scenario.receivers;
  config.parameters = parameters;
  if (scenario.map) config.occupancy_grid = std::make_shared<const OccupancyGrid>(*scenario.map);
  // Placed by hand, as in seed 001: where it starts, unless told otherwise.
  config.initial_pose = initial_pose ? *initial_pose : scenario.trajectory.pose_at(0.0);
  return config;
}

TofDecoderConfig decoder_config_for(const sim::Scenario& scenario) {
  TofDecoderConfig c;
  c.min_range_m = scenario.min_range_m;
  c.max_range_m = scenario.max_range_m;
  c.range_sigma_m = scenario.range_sigma_m;
  return c;
}

TofDecoder scenario_decoder(const sim::Scenario& scenario) {
  TofDecoder decoder(decoder_config_for(scenario));
  decoder.set_beacon_map(BeaconMap(scenario.beacon_list()));
  return decoder;
}

std::vector<SourceEvent> simulate(const sim::Scenario& scenario, std::uint64_t seed, double duration_s) {
  sim::SimSource source(scenario, seed);
  std::vector<SourceEvent> events;
  source.advance(s_to_ns(duration_s), events);
  return events;
}

OfflineStack::OfflineStack(const sim::Scenario& scenario, const std::string& estimator,
                           const std::map<std::string, double>& parameters, std::optional<Pose2> initial_pose)
    : localizer(estimator, estimator_config_for(scenario, parameters, initial_pose)), decoder(decoder_config_for(scenario)) {
  localizer.set_beacon_map(BeaconMap(scenario.beacon_list()));
  decoder.set_beacon_map(BeaconMap(scenario.beacon_list()));
}

std::optional<EstimatorInput> estimator_input(const std::string& robot_id, const SourceEvent& e,
                                              TofDecoder& decoder, BeaconInput beacon_input) {
  switch (e.kind) {
    case SourceEvent::Kind::kOdometry:
      return e.odometry;
    case SourceEvent::Kind::kLaserScan:
      return e.scan;
    case SourceEvent::Kind::kTof:
      if (beacon_input == BeaconInput::kRawTof) return e.tof;
      if (beacon_input != BeaconInput::kRanges) return std::nullopt;
      if (auto out = decoder.decode(robot_id, e.tof); out.range) return out.range->range;
      return std::nullopt;
    case SourceEvent::Kind::kPulse:
      if (beacon_input == BeaconInput::kPulseArrivals) return e.pulse;
      return std::nullopt;
    case SourceEvent::Kind::kTruth:
      return std::nullopt;
  }
  return std::nullopt;
}

std::optional<LocalizerOutput> OfflineStack::feed(const std::string& robot_id, const SourceEvent& e) {
  std::optional<EstimatorInput> input = estimator_input(robot_id, e, decoder, localizer.beacon_input());
  if (!input) return std::nullopt;
  if (const auto* range = std::get_if<RangeMeasurement>(&*input); range && e.true_beacon_id != kBeaconUnidentified) {
    range_truth_[range->stamp_ns] = e.true_beacon_id;
  }
  if (!is_odometry(*input)) {
    // The corrected pose a live localizer publishes at once is not a row here: offline, each
    // odometry sample's pose is scored, and a correction shows in the next one.
    localizer.on_input(robot_id, std::move(*input));
    return std::nullopt;
  }
  auto pose = localizer.on_input(robot_id, std::move(*input));
  for (const auto& a : localizer.take_associations(robot_id)) {
    const auto truth = range_truth_.find(a.range_stamp_ns);
    if (truth == range_truth_.end()) continue;
    AssociationTally::Count& c = associations.by_beacon[truth->second];
    ++c.total;
    if (a.beacon_id == truth->second) ++c.correct;
    range_truth_.erase(truth);
  }
  // Ranges never associated (refused, or a mode without beacons) are forgotten after 10 s.
  range_truth_.erase(range_truth_.begin(), range_truth_.lower_bound(e.stamp_ns - 10'000'000'000));
  return pose;
}

std::optional<double> FiringScheduleRun::converged_s(double position_m, double heading_rad) const {
  std::optional<double> since;
  for (const TrackedPose& p : poses) {
    const bool within = p.position_error_m <= position_m && std::abs(p.heading_error_rad) <= heading_rad;
    if (!within) {
      since.reset();
    } else if (!since) {
      since = p.t_s;
    }
  }
  return since;
}

FiringScheduleRun run_firing_schedule(const sim::Scenario& scenario, std::uint64_t seed, const std::string& estimator,
                                      const std::map<std::string, double>& parameters, FiringSchedule schedule,
                                      std::optional<Pose2> initial_pose) {
  static const std::string kRobot = "robot";
  OfflineStack stack(scenario, estimator, parameters, initial_pose);
  sim::SimSource source(scenario, seed);
  const std::vector<std::uint32_t> every = fire_all(BeaconMap(scenario.beacon_list()));
  FiringScheduler scheduler(scenario.slot_period_ns, {every.begin(), every.end()});
  FiringScheduleRun run;
  std::vector<SourceEvent> events;
  const StampNs end_ns = s_to_ns(scenario.duration_s);
  // Slot by slot: the plan is made from the pose just before each firing (the first slot fires
  // at first_slot_ns), as a localizer refreshing its plan faster than the slots, and the source
  // fires by it as the gateway does (FiringScheduler: checked, judged by its age, and every
  // beacon after unheard planned firings).
  for (StampNs slot_ns = scenario.first_slot_ns;; slot_ns += scenario.slot_period_ns) {
    if (schedule == FiringSchedule::kSelective) {
      if (const std::optional<FiringPlan> plan = stack.localizer.firing_plan(kRobot)) {
        scheduler.take(plan->beacon_ids, plan->stamp_ns, slot_ns);
      }
      source.set_firing_plan(scheduler.plan_at(slot_ns));
    }
    const StampNs until_ns = std::min(slot_ns + scenario.slot_period_ns - 1, end_ns);
    events.clear();
    source.advance(until_ns, events);
    for (const Source::Firing& f : source.take_firings()) scheduler.on_firing(f.planned, f.heard);
    for (const SourceEvent& e : events) {
      if (e.kind == SourceEvent::Kind::kTof) ++run.tofs;
      const std::optional<LocalizerOutput> out = stack.feed(kRobot, e);
      if (!out || !e.has_truth) continue;
      const Pose2 error = out->estimate.pose_map_base - e.truth_map_base;
      const Eigen::Vector2d e_xy = error.head<2>();
      const Eigen::LDLT<Eigen::Matrix2d> p_xy(out->estimate.covariance.topLeftCorner<2, 2>());
      const double nees = p_xy.info() == Eigen::Success && p_xy.isPositive() ? e_xy.dot(p_xy.solve(e_xy))
                                                                             : std::numeric_limits<double>::infinity();
      run.poses.push_back({ns_to_s(e.stamp_ns), e_xy, e_xy.norm(), wrap_angle_rad(error.z()), nees,
                           out->estimate.status});
    }
    if (until_ns == end_ns) break;
  }
  run.slots_fired = source.firing_counts().fired;
  run.slots_heard = source.firing_counts().heard;
  run.rejections.add_rejections(stack.localizer.counts(), "localizer.");
  return run;
}

std::size_t AssociationTally::total() const {
  std::size_t n = 0;
  for (const auto& [id, c] : by_beacon) n += c.total;
  return n;
}

std::size_t AssociationTally::correct() const {
  std::size_t n = 0;
  for (const auto& [id, c] : by_beacon) n += c.correct;
  return n;
}

std::vector<SourceEvent> deliver(std::vector<SourceEvent> events, const Delivery& delivery,
                                 std::uint64_t seed) {
  if (delivery.max_measurement_delay_ns <= 0) return events;
  std::mt19937_64 rng(seed ^ 0x5deece66dULL);
  std::uniform_int_distribution<StampNs> delay_ns(0, delivery.max_measurement_delay_ns);
  std::vector<std::pair<StampNs, std::size_t>> arrival;
  arrival.reserve(events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    const bool measurement =
        events[i].kind == SourceEvent::Kind::kTof || events[i].kind == SourceEvent::Kind::kPulse ||
        events[i].kind == SourceEvent::Kind::kLaserScan;
    arrival.emplace_back(events[i].stamp_ns + (measurement ? delay_ns(rng) : 0), i);
  }
  std::stable_sort(arrival.begin(), arrival.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<SourceEvent> out;
  out.reserve(events.size());
  for (const auto& [at_ns, i] : arrival) out.push_back(std::move(events[i]));
  return out;
}

OfflineRunResult run_scenario_offline(const sim::Scenario& scenario, std::uint64_t seed,
                                      const std::string& estimator,
                                      const std::vector<std::string>& parameters, double settle_s,
                                      const Delivery& delivery) {
  OfflineStack stack(scenario, estimator, parse_estimator_parameters(parameters, "parameter"));
  TruthTrack truth;
  std::vector<EstimateRow> rows;
  const std::vector<SourceEvent> events = simulate(scenario, seed, scenario.duration_s);
  OfflineRunResult result;
  for (const auto& e : deliver(events, delivery, seed)) {
    if (e.kind == SourceEvent::Kind::kOdometry) truth.add(e.stamp_ns, e.truth_map_base);
    if (auto pose = stack.feed("robot", e)) {
      rows.push_back({"robot", pose->estimate, estimator});
      if (!pose->state.empty()) result.last_state = pose->state;
    }
  }
  result.poses = rows.size();
  for (auto row = rows.rbegin(); row != rows.rend(); ++row) {
    if (const auto at = truth.at(row->estimate.stamp_ns)) {
      result.last_position_error_m = (row->estimate.pose_map_base.head<2>() - at->pose_map_base.head<2>()).norm();
      result.last_status = row->estimate.status;
      break;
    }
  }
  result.associations = stack.associations;
  result.rejections.add_rejections(stack.decoder.counts(), "decoder.");
  result.rejections.add_rejections(stack.localizer.counts(), "localizer.");
  result.replays = stack.localizer.replays();
  EvaluationOptions options;
  if (!rows.empty()) {
    options.score_from_ns = std::max(rows.front().estimate.stamp_ns + s_to_ns(settle_s), s_to_ns(scenario.score_from_s));
  }
  result.metrics = evaluate(truth, rows, options);
  std::vector<StampNs> scored_ns;
  for (const EstimateRow& row : rows) {
    if (row.estimate.stamp_ns >= options.score_from_ns) scored_ns.push_back(row.estimate.stamp_ns);
  }
  result.bound = pose_bound_of_run(scenario, events, scored_ns,
                                   {stack.localizer.uses_laser(), stack.localizer.localizes_from_beacons(), false});
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

namespace {

double quadratic_mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

}  // namespace

std::string bound_table_markdown(const std::vector<AccuracyRow>& rows) {
  std::ostringstream out;
  out << "| scenario | estimator | seeds | E_p RMS (m) | bound (m) | E_p / bound | E_phi RMS (deg) | bound (deg) | "
         "E_phi / bound |\n"
      << "|---|---|---|---|---|---|---|---|---|\n";
  char text[160];
  for (const auto& row : rows) {
    out << "| " << row.scenario << " | " << row.estimator << " | " << row.runs.size() << " | ";
    if (row.bounds.size() != row.runs.size() || row.runs.empty()) {
      out << "n/a | n/a: " << (row.bound_unavailable.empty() ? "no run scored" : row.bound_unavailable)
          << " | | | | |\n";
      continue;
    }
    std::vector<double> ep, bound_p, ephi, bound_phi;
    bool same_poses = true;
    for (std::size_t i = 0; i < row.runs.size(); ++i) {
      same_poses = same_poses && row.bounds[i].samples == row.runs[i].samples;
      ep.push_back(row.runs[i].position_rms_m);
      bound_p.push_back(row.bounds[i].position_m);
      if (row.runs[i].heading_rms_deg) {
        ephi.push_back(*row.runs[i].heading_rms_deg);
        bound_phi.push_back(row.bounds[i].heading_deg);
      }
    }
    const auto ratio = [&](double ours, double bound) { return bound_ratio(row.laser_fused, same_poses, ours, bound); };
    std::snprintf(text, sizeof text, "%.4f | %.4f | ", quadratic_mean(ep), quadratic_mean(bound_p));
    out << text << ratio(quadratic_mean(ep), quadratic_mean(bound_p)) << " | ";
    if (ephi.empty()) {
      out << "n/a | n/a | n/a |\n";
      continue;
    }
    std::snprintf(text, sizeof text, "%.3f | %.3f | ", quadratic_mean(ephi), quadratic_mean(bound_phi));
    out << text << ratio(quadratic_mean(ephi), quadratic_mean(bound_phi)) << " |\n";
  }
  return out.str();
}

std::string distance_table_markdown(const std::vector<AccuracyRow>& rows) {
  std::set<std::uint32_t> beacon_ids;
  for (const auto& row : rows) {
    for (const auto& tally : row.associations) {
      for (const auto& [id, c] : tally.by_beacon) beacon_ids.insert(id);
    }
  }
  std::ostringstream out;
  out << "| scenario | estimator | seeds | mean (m) | std (m) | RMSE (m) | max (m) |";
  for (auto id : beacon_ids) out << " association B" << id << " |";
  out << " association, all |\n|---|---|---|---|---|---|---|";
  for (std::size_t i = 0; i <= beacon_ids.size(); ++i) out << "---|";
  out << '\n';
  for (const auto& row : rows) {
    std::vector<double> mean, sd, rms, max;
    for (const auto& m : row.runs) {
      mean.push_back(m.position_mean_m);
      rms.push_back(m.position_rms_m);
      max.push_back(m.position_max_m);
      sd.push_back(std::sqrt(
          std::max(0.0, m.position_rms_m * m.position_rms_m - m.position_mean_m * m.position_mean_m)));
    }
    out << "| " << row.scenario << " | " << row.estimator << " | " << row.runs.size() << " | "
        << mean_and_spread(mean, 4) << " | " << mean_and_spread(sd, 4) << " | " << mean_and_spread(rms, 4)
        << " | " << mean_and_spread(max, 4) << " |";
    auto rate = [&](std::optional<std::uint32_t> id) {
      std::vector<double> rates;
      for (const auto& tally : row.associations) {
        std::size_t total = 0, correct = 0;
        if (id) {
          const auto it = tally.by_beacon.find(*id);
          if (it != tally.by_beacon.end()) total = it->second.total, correct = it->second.correct;
        } else {
          total = tally.total();
          correct = tally.correct();
        }
        if (total) rates.push_back(100.0 * static_cast<double>(correct) / static_cast<double>(total));
      }
      return rates.empty() ? std::string("n/a") : mean_and_spread(rates, 1) + " %";
    };
    for (auto id : beacon_ids) out << ' ' << rate(id) << " |";
    out << ' ' << rate(std::nullopt) << " |\n";
  }
  return out.str();
}

std::string path_table_markdown(const std::vector<AccuracyRow>& rows) {
  std::ostringstream out;
  out << "| scenario | estimator | seeds | path error std (m) | path error max (m) | largest max (m) | E_p RMS (m) | "
         "E_phi RMS (deg) | NEES in band |\n"
      << "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& row : rows) {
    std::vector<double> sd, max, ep, ephi, nees;
    for (const auto& m : row.runs) {
      if (m.path_error_std_m) sd.push_back(*m.path_error_std_m);
      if (m.path_error_max_m) max.push_back(*m.path_error_max_m);
      ep.push_back(m.position_rms_m);
      if (m.heading_rms_deg) ephi.push_back(*m.heading_rms_deg);
      nees.push_back(m.nees_in_band_fraction);
    }
    char largest[32] = "n/a";
    if (!max.empty()) std::snprintf(largest, sizeof largest, "%.4f", *std::max_element(max.begin(), max.end()));
    out << "| " << row.scenario << " | " << row.estimator << " | " << row.runs.size() << " | "
        << mean_and_spread(sd, 4) << " | " << mean_and_spread(max, 4) << " | " << largest << " | "
        << mean_and_spread(ep, 4) << " | " << mean_and_spread(ephi, 2) << " | " << mean_and_spread(nees, 2) << " |\n";
  }
  return out.str();
}

}  // namespace beaconloc
