#include "pipeline.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "beaconloc/core/decimal.hpp"
#include "beaconloc/core/limits.hpp"
#include "beaconloc/core/occupancy_grid_io.hpp"
#include "beaconloc/dds/stop_signal.hpp"
#include "decoder_participant.hpp"
#include "diagnostics_recorder.hpp"
#include "estimator_plugins.hpp"
#include "estimator_state_recorder.hpp"
#include "lead_limiter.hpp"
#include "offline_run.hpp"
#include "localizer_participant.hpp"
#include "options.hpp"
#include "pose_recorder.hpp"
#include "sim/faults.hpp"
#include "sim/scenario_yaml.hpp"
#include "sim/sim_source.hpp"
#include "svg_plot.hpp"

extern char** environ;

namespace beaconloc::cli {

LocalizerSettings with_scenario_defaults(LocalizerSettings s, const LoadedSource& source,
                                         const std::string& out_dir);

namespace {

using namespace std::chrono_literals;

// Samples a participant may still have to take before the gateway writes more: well inside the
// reader histories (examples/qos/topics.xml: odometry 50, TOF and ranges 16), so a run in one
// process as fast as the machine goes loses nothing.
constexpr std::uint64_t kMaxOdometryLead = 25;
constexpr std::uint64_t kMaxTofLead = 8;
// A consumer that takes nothing for this long while it lacks samples lost them on the way.
constexpr auto kLostAfter = 2s;
// How long the gateway's first sample waits for its beacon map to reach the consumers.
constexpr auto kMapDeliveryTimeout = 5s;

class ChildProcess {
 public:
  ChildProcess(const std::string& exe, const std::vector<std::string>& args, const std::string& log)
      : log_(log) {
    std::vector<std::string> argv{exe};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> c_argv;
    for (auto& a : argv) c_argv.push_back(a.data());
    c_argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    const int rc = posix_spawn(&pid_, exe.c_str(), &actions, nullptr, c_argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("cannot start " + exe);
  }
  ~ChildProcess() {
    if (pid_ > 0 && !done_) {
      ::kill(pid_, SIGTERM);
      wait(10s);
      if (!done_) {
        ::kill(pid_, SIGKILL);
        wait(10s);
      }
    }
  }
  // Exit code, or -1 while running after the timeout.
  int wait(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (!done_) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        done_ = true;
        code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        break;
      }
      if (std::chrono::steady_clock::now() > end) return -1;
      std::this_thread::sleep_for(20ms);
    }
    return code_;
  }
  void terminate() {
    if (!done_) ::kill(pid_, SIGTERM);
  }
  bool done() {
    wait(0ms);
    return done_;
  }
  const std::string& log() const { return log_; }

 private:
  pid_t pid_ = -1;
  bool done_ = false;
  int code_ = -1;
  std::string log_;
};

// Waits until each participant (its report name, its process) has reported once: it runs and
// its readers exist, so that the gateway started next loses none of its first samples, however
// slowly they started. Throws if one exits first, or does not report within kStartTimeout.
void wait_until_reporting(const DiagnosticsRecorder& diagnostics,
                          const std::vector<std::pair<std::string, ChildProcess*>>& participants) {
  constexpr auto kStartTimeout = 60s;
  const auto give_up = std::chrono::steady_clock::now() + kStartTimeout;
  for (const auto& [name, process] : participants) {
    while (!diagnostics.latest().count(name)) {
      if (process->done()) {
        throw std::runtime_error(name + " exited at its start (code " + std::to_string(process->wait(0ms)) +
                                 "); see " + process->log());
      }
      if (dds::wait_for_stop(20ms)) throw std::runtime_error("stopped before " + name + " started");
      if (std::chrono::steady_clock::now() > give_up) {
        throw std::runtime_error(name + " did not report within " + std::to_string(kStartTimeout.count()) +
                                 " s of its start; see " + process->log());
      }
    }
  }
}

// Waits until this process has heard each participant named leave the bus (its dispose when it
// stopped, or the end of its writer), at most kLeaveTimeout: a process that exited has sent its
// dispose, but this reader may not have taken it yet, and its report would still show it alive.
void wait_until_left(const DiagnosticsRecorder& diagnostics, const std::vector<std::string>& names) {
  constexpr auto kLeaveTimeout = 3s;
  const auto give_up = std::chrono::steady_clock::now() + kLeaveTimeout;
  auto left = [&] {
    const auto reports = diagnostics.reports();
    for (const auto& name : names) {
      const auto it = reports.find(name);
      if (it != reports.end() &&
          (it->second.liveness == Liveness::kAlive || it->second.liveness == Liveness::kSilent))
        return false;
    }
    return true;
  };
  while (!left() && std::chrono::steady_clock::now() < give_up) std::this_thread::sleep_for(20ms);
}

// Waits until the pipeline has drained after the gateway ended: no new pose for kQuiet (a
// localizer still working through what it holds publishes at the odometry rate), at most
// kMaxDrain.
void wait_until_drained(const PoseRecorder& recorder) {
  constexpr auto kQuiet = 1s;
  constexpr auto kMaxDrain = 15s;
  const auto give_up = std::chrono::steady_clock::now() + kMaxDrain;
  std::size_t seen = recorder.count();
  auto quiet_since = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < give_up && !dds::wait_for_stop(20ms)) {
    const std::size_t now_seen = recorder.count();
    if (now_seen != seen) {
      seen = now_seen;
      quiet_since = std::chrono::steady_clock::now();
    } else if (std::chrono::steady_clock::now() - quiet_since >= kQuiet) {
      return;
    }
  }
}

// "x:y,x:y,...", each number written to read back exactly (exact_number).
std::string join_receivers(const ReceiverArray& receivers) {
  std::string s;
  for (std::size_t i = 0; i < receivers.size(); ++i) {
    s += (i ? "," : "") + exact_number(receivers.receivers_base_m[i].x()) + ':' +
         exact_number(receivers.receivers_base_m[i].y());
  }
  return s;
}

void print_pose_line(double t_s, const PoseRecorder& recorder) {
  const auto newest = recorder.newest();
  if (!newest) {
    std::printf("t=%6.1f s  no pose yet (initializing from beacons)\n", t_s);
  } else {
    const auto& p = newest->row.estimate;
    std::printf("t=%6.1f s  pose x %.3f m  y %.3f m  yaw %6.1f deg  %s\n", t_s, p.pose_map_base.x(),
                p.pose_map_base.y(), p.pose_map_base.z() * 180.0 / M_PI, to_string(p.status));
  }
  std::fflush(stdout);
}

// The posterior Cramer-Rao bound over the poses scored (docs/bound.md), from the scenario's events
// as the simulator gives them for the seed, or why there is none.
PoseBoundResult bound_of_run(const PipelineOptions& o, const LoadedSource& source, const std::vector<RecordedPose>& poses,
                             const TruthTrack& truth, const EvaluationOptions& eval) {
  const sim::Scenario& scenario = *source.scenario;
  // What the estimator that ran is, from the settings it ran with (as run_in_one_process builds
  // them; no map file is written again).
  BoundedEstimator estimator;
  estimator.poses_corrected = true;  // PoseRecorder keeps the newest pose per stamp
  try {
    EstimatorConfig config = with_scenario_defaults(o.localizer, source, "").config(scenario.receivers);
    if (!config.occupancy_grid && scenario.map) config.occupancy_grid = std::make_shared<const OccupancyGrid>(*scenario.map);
    const LocalizerCore probe(o.localizer.estimator, std::move(config));
    estimator.laser_fused = probe.uses_laser();
    estimator.localizes_from_beacons = probe.localizes_from_beacons();
  } catch (const std::exception& e) {
    return {std::nullopt, std::string("the estimator could not be asked what it fuses: ") + e.what(), false};
  }
  if (o.localizer.selective_activation()) {
    return {std::nullopt, "selective firing: the bound follows the scenario's own firing order", estimator.laser_fused};
  }
  const double duration_s = std::max(o.gateway.duration_s, scenario.duration_s);
  const std::vector<SourceEvent> events = simulate(scenario, source.seed, duration_s);
  // A gateway pacing in real time offsets the simulated stamps to the wall clock at its start:
  // the truth's first sample is the first odometry sample's.
  StampNs offset_ns = 0;
  const auto first_odometry = std::find_if(events.begin(), events.end(), [](const SourceEvent& e) {
    return e.kind == SourceEvent::Kind::kOdometry;
  });
  if (!truth.empty() && first_odometry != events.end()) {
    offset_ns = truth.samples().begin()->first - first_odometry->stamp_ns;
  }
  std::vector<StampNs> scored_ns;
  for (const RecordedPose& p : poses) {
    if (p.row.estimate.stamp_ns >= eval.score_from_ns) scored_ns.push_back(p.row.estimate.stamp_ns - offset_ns);
  }
  return pose_bound_of_run(scenario, events, scored_ns, estimator);
}

// Each value the estimator published, at its newest stamp: "name value +- sigma, ...".
std::string newest_state(const std::vector<EstimatorStateRow>& state) {
  std::map<std::string, const EstimatorStateRow*> newest;
  for (const EstimatorStateRow& row : state) {
    const EstimatorStateRow*& at = newest[row.robot_id + " " + row.value.name];
    if (!at || row.stamp_ns >= at->stamp_ns) at = &row;
  }
  std::string out;
  for (const auto& [key, row] : newest) {
    char text[160];
    std::snprintf(text, sizeof text, "%s%s %.6g +- %.3g", out.empty() ? "" : ", ", key.c_str(), row->value.value,
                  row->value.sigma);
    out += text;
  }
  return out;
}

// Scores and writes the outputs shared by both modes.
PipelineResult finish(const PipelineOptions& o, const LoadedSource& source, const BeaconMap& beacons,
                      const std::vector<RecordedPose>& poses, const TruthTrack& truth,
                      const std::string& diagnostics, const std::vector<EstimatorStateRow>& state) {
  PipelineResult r;
  EvaluationOptions eval;
  // A scenario is scored from its score_from_s (seed 002: from 20 s, as the paper), as
  // `beaconloc accuracy` scores it (offline_run.cpp); simulated time starts at 0.
  if (source.scenario) eval.score_from_ns = s_to_ns(source.scenario->score_from_s);
  const PoseRunSummary s = summarize(poses, truth, eval);
  r.poses = s.poses;
  r.pose_rate_hz = s.pose_rate_hz;
  r.metrics = s.metrics;
  r.truth_samples = truth.size();
  r.diagnostics = diagnostics;
  if (!o.out_dir.empty()) {
    const auto rows = rows_of(poses);
    write_estimates_csv(o.out_dir + "/estimate.csv", rows);
    write_beacon_map_csv(o.out_dir + "/beacons.csv", beacons);
    write_metrics_json(o.out_dir + "/metrics.json", r.metrics, o.localizer.estimator, source.label);
    const std::string title = source.label + ", " + o.localizer.estimator;
    write_trajectory_svg(o.out_dir + "/trajectory.svg", title, truth, rows, beacons,
                         source.scenario ? source.scenario->map : std::nullopt);
    write_error_svg(o.out_dir + "/error.svg", title, error_series(truth, rows, eval));
    if (!state.empty()) write_estimator_state_csv(o.out_dir + "/estimator_state.csv", state);
  }
  r.estimator_state_rows = state.size();
  r.newest_state = newest_state(state);
  // After the files: whatever the bound meets, the run's outputs are written.
  if (source.scenario) r.bound = bound_of_run(o, source, poses, truth, eval);
  return r;
}

PipelineResult run_in_one_process(const PipelineOptions& o, LoadedSource source) {
  std::mutex truth_mutex;
  TruthTrack truth;
  const BeaconMap beacons = source.source->beacon_map();
  const LocalizerSettings settings = with_scenario_defaults(o.localizer, source, o.out_dir);
  EstimatorConfig config = settings.config(source.source->receivers());
  if (!config.occupancy_grid && source.scenario && source.scenario->map) {  // no --out: no map file
    config.occupancy_grid = std::make_shared<const OccupancyGrid>(*source.scenario->map);
  }
  LocalizerParticipant localizer(o.dds, LocalizerCore(o.localizer.estimator, config, o.localizer.robot),
                                 {o.localizer.calibration_file, o.localizer.selective_activation()});
  std::unique_ptr<bridge::BridgeParticipant> ros2_bridge;
  if (o.bridge) {
    bridge::BridgeOptions b = *o.bridge;
    b.receivers = config.receivers;
    b.robot_id = o.gateway.robot_id;
    ros2_bridge = std::make_unique<bridge::BridgeParticipant>(o.dds, b);
  }
  DecoderParticipant decoder(o.dds, o.decoder);
  PoseRecorder recorder(o.dds);
  EstimatorStateRecorder state_recorder(o.dds);
  DiagnosticsRecorder diagnostics(o.dds);
  std::unique_ptr<GatewayParticipant> gateway;
  std::uint64_t stalls = 0;
  // The streams the gateway is held back on, in this order: odometry (to the localizer), TOFs (to
  // the decoder) and the decoder's ranges (to the localizer); from beacons without a radio
  // message, the pulse arrivals go to the localizer and the decoder has nothing to do.
  enum : std::size_t { kOdometry, kTofs, kRanges };
  const bool pulses = source.source->beacon_input() == BeaconInput::kPulseArrivals;
  LeadLimiter lead({kMaxOdometryLead, kMaxTofLead, kMaxTofLead});
  auto streams = [&] {
    const auto& written = gateway->progress();
    if (pulses) {
      return std::vector<LeadLimiter::Stream>{{written.odometry_written.load(), localizer.odometry_processed()},
                                              {written.tofs_written.load(), localizer.ranges_processed()},
                                              {0, 0}};
    }
    return std::vector<LeadLimiter::Stream>{{written.odometry_written.load(), localizer.odometry_processed()},
                                            {written.tofs_written.load(), decoder.tofs_processed()},
                                            {decoder.ranges_written(), localizer.ranges_processed()}};
  };
  auto processed = [](const std::vector<LeadLimiter::Stream>& now) {
    std::uint64_t n = 0;
    for (const auto& s : now) n += s.processed;
    return n;
  };
  bool map_delivered = false;
  auto throttle = [&] {
    // Before the first sample: hold the gateway until its beacon map (written first, on a topic of
    // its own) has reached the localizer and the decoder, else their first ranges and TOFs would
    // be refused as no_beacon_map for overtaking it (a reliable resend of a lost map sample waits
    // for the writer's heartbeat). Not beyond kMapDeliveryTimeout: then the refusals are counted.
    if (!map_delivered) {
      const auto give_up = std::chrono::steady_clock::now() + kMapDeliveryTimeout;
      while (!(localizer.has_beacon_map() && (pulses || decoder.has_beacon_map())) &&
             std::chrono::steady_clock::now() < give_up) {
        std::this_thread::sleep_for(1ms);
      }
      map_delivered = true;
    }
    // Hold the gateway back while the decoder or the localizer lags (speed 0: as fast as they go),
    // as long as they take samples: what they lack when they took none for kLostAfter was lost.
    auto now = streams();
    std::uint64_t taken = processed(now);
    auto taken_at = std::chrono::steady_clock::now();
    while (lead.lagging(now)) {
      std::this_thread::sleep_for(50us);
      now = streams();
      if (processed(now) != taken) {
        taken = processed(now);
        taken_at = std::chrono::steady_clock::now();
      } else if (std::chrono::steady_clock::now() - taken_at > kLostAfter) {
        ++stalls;
        lead.give_up(now);
        return;
      }
    }
  };
  LoadedSource described{source.choice, source.seed, nullptr, source.scenario, source.label};
  GatewayOptions gateway_options = o.gateway;
  // --wait-for-readers counts readers besides the run's own: the decoder (or, of pulses, the
  // localizer) on the beacons' topic; the localizer and the bridge on odometry.
  gateway_options.own_beacon_readers = 1;
  gateway_options.own_odometry_readers = ros2_bridge ? 2 : 1;
  gateway = std::make_unique<GatewayParticipant>(
      o.dds, gateway_options, std::move(source.source),
      [&](StampNs stamp, const Pose2& pose, bool has_yaw) {
        std::lock_guard<std::mutex> lock(truth_mutex);
        truth.add(stamp, pose, has_yaw);
      },
      o.gateway.speed == 0.0 ? GatewayParticipant::Throttle(throttle) : GatewayParticipant::Throttle());
  if (!gateway->wait_for_readers(5s) || (!pulses && !decoder.wait_for_readers(5s))) {
    throw std::runtime_error("the participants did not discover each other within 5 s");
  }
  gateway->start();
  const auto start = std::chrono::steady_clock::now();
  double next_pose_s = 1.0, next_progress_s = 2.0;
  while (!gateway->finished() && !dds::wait_for_stop(50ms)) {
    if (o.print_poses && gateway->elapsed_s() >= next_pose_s) {
      print_pose_line(gateway->elapsed_s(), recorder);
      next_pose_s += 1.0;
    }
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o.print_progress && wall_s >= next_progress_s) {
      std::printf("run: %.1f of %.1f s of data (%.0f%%), %zu poses\n", gateway->elapsed_s(),
                  gateway->total_s(), 100.0 * gateway->elapsed_s() / std::max(gateway->total_s(), 1e-9),
                  recorder.count());
      std::fflush(stdout);
      next_progress_s += 2.0;
    }
  }
  gateway->stop();
  gateway->rethrow_failure();
  // Let the last samples through the pipeline.
  const auto drain_until = std::chrono::steady_clock::now() + 3s;
  auto draining = [&] {
    const auto now = streams();
    return lead.missing(kOdometry, now[kOdometry]) > 0 || lead.missing(kRanges, now[kRanges]) > 0;
  };
  while (std::chrono::steady_clock::now() < drain_until && draining()) std::this_thread::sleep_for(10ms);
  std::this_thread::sleep_for(100ms);
  if (stalls) {
    std::printf(
        "run: the gateway waited for a lost sample %llu time(s); lost %llu odometry, %llu TOF, %llu range "
        "sample(s)\n",
        static_cast<unsigned long long>(stalls), static_cast<unsigned long long>(lead.lost(kOdometry)),
        static_cast<unsigned long long>(lead.lost(kTofs)),
        static_cast<unsigned long long>(lead.lost(kRanges)));
  }
  gateway->publish_diagnostics();
  decoder.publish_diagnostics();
  localizer.publish_diagnostics();
  std::this_thread::sleep_for(200ms);
  std::ostringstream diag;
  print_diagnostics(diagnostics.reports(), diag);
  std::lock_guard<std::mutex> lock(truth_mutex);
  return finish(o, described, beacons, recorder.poses(), truth, diag.str(), state_recorder.rows());
}

// The arguments a child process is started with: option groups written back (options.hpp).
template <class... Sets>
std::vector<std::string> command_line(std::string command, const Sets&... sets) {
  std::vector<std::string> out{std::move(command)};
  for (const OptionSet* set : {&sets...}) {
    for (std::string& a : set->arguments()) out.push_back(std::move(a));
  }
  return out;
}

PipelineResult run_in_processes(const PipelineOptions& o, LoadedSource source, const std::string& exe) {
  if (o.out_dir.empty())
    throw std::invalid_argument("--processes needs --out (the participants' logs go there)");
  if (!(o.gateway.speed > 0.0)) {
    throw std::invalid_argument(
        "--processes needs --speed > 0: separate processes cannot hold the gateway back");
  }
  const BeaconMap beacons = source.source->beacon_map();
  const ReceiverArray receivers = source.source->receivers();
  PoseRecorder recorder(o.dds);
  EstimatorStateRecorder state_recorder(o.dds);
  DiagnosticsRecorder diagnostics(o.dds);

  const LocalizerSettings localizer_settings = with_scenario_defaults(o.localizer, source, o.out_dir);
  // An unknown estimator or a bad parameter fails here, at start, rather than in the child's log.
  [[maybe_unused]] const LocalizerCore checked(localizer_settings.estimator,
                                               localizer_settings.config(receivers));
  dds::DdsOptions dds = o.dds;
  std::vector<std::string> localizer_args = command_line("localizer", dds_option_set(dds));
  for (const auto& a : localizer_settings.arguments(receivers)) localizer_args.push_back(a);
  TofDecoderConfig decoder_config = o.decoder;
  double max_age_ms = max_age_ms_of(o.decoder);
  const std::vector<std::string> decoder_args =
      command_line("decoder", dds_option_set(dds), decoder_option_set(decoder_config, max_age_ms));
  GatewayOptions gateway_options = o.gateway;
  gateway_options.truth_csv = o.out_dir + "/truth.csv";
  // Besides the run's own readers (its decoder or localizer on the beacons' topic, its localizer on
  // odometry): one each. The child gets the total, its own being none.
  if (gateway_options.wait_for_readers > 0) gateway_options.wait_for_readers += 1;
  std::optional<std::uint64_t> seed = o.gateway.seed;
  SourceChoice choice = source.choice;
  const std::vector<std::string> gateway_args = command_line(
      "gateway", dds_option_set(dds), gateway_option_set(gateway_options, seed), source_option_set(choice));

  // From beacons without a radio message the gateway's pulse arrivals go to the localizer: no
  // decoder (it would have nothing to decode).
  const bool pulses = source.source->beacon_input() == BeaconInput::kPulseArrivals;
  ChildProcess localizer(exe, localizer_args, o.out_dir + "/localizer.log");
  std::optional<ChildProcess> decoder;
  if (!pulses) decoder.emplace(exe, decoder_args, o.out_dir + "/decoder.log");
  std::vector<std::pair<std::string, ChildProcess*>> reporting{{"beaconloc.localizer." + o.localizer.estimator, &localizer}};
  if (decoder) reporting.emplace_back("beaconloc.decoder", &*decoder);
  wait_until_reporting(diagnostics, reporting);
  ChildProcess gateway(exe, gateway_args, o.out_dir + "/gateway.log");
  const auto start = std::chrono::steady_clock::now();
  const double total_s = o.gateway.duration_s > 0.0
                             ? o.gateway.duration_s
                             : ns_to_s(source.source->last_stamp_ns() - source.source->first_stamp_ns());
  double next_progress_s = 2.0;
  while (!gateway.done() && !dds::wait_for_stop(100ms)) {
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o.print_progress && wall_s >= next_progress_s) {
      std::printf("run: ~%.0f of %.1f s of data, %zu poses\n", std::min(wall_s * o.gateway.speed, total_s),
                  total_s, recorder.count());
      std::fflush(stdout);
      next_progress_s += 2.0;
    }
  }
  const int gateway_code = gateway.wait(dds::stop_requested() ? 0ms : 10s);
  if (!dds::stop_requested()) wait_until_drained(recorder);
  if (decoder) decoder->terminate();
  localizer.terminate();
  const int decoder_code = decoder ? decoder->wait(15s) : 0, localizer_code = localizer.wait(15s);
  if (gateway_code != 0 || decoder_code != 0 || localizer_code != 0) {
    throw std::runtime_error("a participant failed (exit codes gateway " + std::to_string(gateway_code) +
                             ", decoder " + std::to_string(decoder_code) + ", localizer " +
                             std::to_string(localizer_code) + "); logs in " + o.out_dir);
  }
  std::vector<std::string> participants{"beaconloc.gateway." + o.gateway.robot_id,
                                        "beaconloc.localizer." + o.localizer.estimator};
  if (decoder) participants.push_back("beaconloc.decoder");
  wait_until_left(diagnostics, participants);
  std::ostringstream diag;
  print_diagnostics(diagnostics.reports(), diag);
  return finish(o, source, beacons, recorder.poses(), load_truth_csv(o.out_dir + "/truth.csv"), diag.str(),
                state_recorder.rows());
}

std::vector<std::pair<std::string, std::string>> split_pairs(const std::string& text, char outer,
                                                             char inner) {
  std::vector<std::pair<std::string, std::string>> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, outer)) {
    const auto at = item.find(inner);
    out.emplace_back(item.substr(0, at), at == std::string::npos ? std::string() : item.substr(at + 1));
  }
  return out;
}

// A coordinate of --receivers: decimal (core/decimal.hpp), within kMaxReceiverOffsetM of the
// robot's centre.
double receiver_coordinate(const std::string& text) {
  const double v = decimal_or_throw(text, "--receivers");
  if (std::abs(v) > kMaxReceiverOffsetM)
    throw std::invalid_argument(range_problem("--receivers", v, -kMaxReceiverOffsetM, kMaxReceiverOffsetM));
  return v;
}

}  // namespace

LoadedSource load_source(const SourceChoice& choice, std::optional<std::uint64_t> seed) {
  LoadedSource out;
  out.choice = choice;
  if (!choice.replay_dir.empty()) {
    if (!choice.faults.empty()) throw std::invalid_argument("--fault needs a simulated source, not --replay");
    auto replay = std::make_unique<ReplaySource>(choice.replay_dir, choice.replay);
    for (const auto& problem : replay->load_problems())
      std::fprintf(stderr, "replay: refused %s\n", problem.c_str());
    for (const auto& note : replay->load_notes()) std::fprintf(stderr, "replay: note: %s\n", note.c_str());
    out.label = "replay " + std::filesystem::path(choice.replay_dir).filename().string();
    if (out.label == "replay ") out.label = "replay " + choice.replay_dir;
    out.seed = seed.value_or(1);
    out.source = std::move(replay);
    return out;
  }
  sim::Scenario scenario =
      choice.scenario_file.empty() ? sim::default_scenario() : sim::load_scenario_file(choice.scenario_file);
  for (const auto& fault : choice.faults) sim::apply_fault(scenario, fault);
  out.seed = seed.value_or(scenario.seed);
  out.label = "scenario " + scenario.name;
  out.scenario = scenario;
  out.source = std::make_unique<sim::SimSource>(scenario, out.seed);
  return out;
}

EstimatorConfig LocalizerSettings::config(const std::optional<ReceiverArray>& fallback) const {
  EstimatorConfig c;
  if (!receivers.empty()) {
    for (const auto& [x, y] : split_pairs(receivers, ',', ':')) {
      c.receivers.receivers_base_m.emplace_back(receiver_coordinate(x), receiver_coordinate(y));
    }
    c.receivers.receiver_height_m = receiver_height_m;
  } else if (fallback) {
    c.receivers = *fallback;
  } else {
    c.receivers = ReceiverArray::on_circle(receiver_radius_m, receiver_count);
    c.receivers.receiver_height_m = receiver_height_m;
  }
  c.parameters = parse_estimator_parameters(parameters, "--param");
  if (!map_file.empty())
    c.occupancy_grid = std::make_shared<const OccupancyGrid>(load_occupancy_grid(map_file));
  if (!initial_pose.empty()) {
    if (initial_pose.size() != 3) throw std::invalid_argument("--initial-pose takes X Y YAW");
    c.initial_pose = Pose2(initial_pose[0], initial_pose[1], initial_pose[2]);
  }
  return c;
}

// What a simulated source tells a localizer that was not told otherwise: the scenario's map,
// written as a map file in out_dir, and its start pose (the robot placed by hand).
LocalizerSettings with_scenario_defaults(LocalizerSettings s, const LoadedSource& source,
                                         const std::string& out_dir) {
  if (!source.scenario) return s;
  if (s.map_file.empty() && source.scenario->map && !out_dir.empty()) {
    s.map_file = out_dir + "/map.yaml";
    write_occupancy_grid(*source.scenario->map, s.map_file);
  }
  if (s.initial_pose.empty()) {
    const Pose2 start = source.scenario->trajectory.pose_at(0.0);
    s.initial_pose = {start.x(), start.y(), start.z()};
  }
  return s;
}

std::vector<std::string> LocalizerSettings::arguments(const std::optional<ReceiverArray>& fallback) const {
  // The receivers the settings resolve to, given explicitly: the child has no source to ask.
  const EstimatorConfig c = config(fallback);
  LocalizerSettings child = *this;
  child.receivers = join_receivers(c.receivers);
  child.receiver_height_m = c.receivers.receiver_height_m;
  return localizer_option_set(child, true).arguments();
}

PipelineResult run_pipeline(const PipelineOptions& options, LoadedSource source,
                            const std::string& self_exe) {
  if (!options.out_dir.empty()) std::filesystem::create_directories(options.out_dir);
  // Here too with --processes (the localizer process loads them again): a bad plugin is refused
  // before any participant starts.
  load_estimator_plugins(options.localizer.estimator_plugins);
  return options.processes ? run_in_processes(options, std::move(source), self_exe)
                           : run_in_one_process(options, std::move(source));
}

Metrics evaluate_files(const std::string& truth_csv, const std::string& estimate_csv,
                       const std::string& out_dir, const std::string& beacons_csv, double max_truth_gap_s) {
  const TruthTrack truth = load_truth_csv(truth_csv);
  const auto rows = load_estimates_csv(estimate_csv);
  const BeaconMap beacons = beacons_csv.empty() ? BeaconMap() : load_beacon_map_csv(beacons_csv);
  EvaluationOptions eval;
  eval.max_truth_gap_ns = s_to_ns(max_truth_gap_s);
  const Metrics m = evaluate(truth, rows, eval);
  std::filesystem::create_directories(out_dir);
  const std::string estimator = rows.empty() ? std::string() : rows.front().estimator;
  write_metrics_json(out_dir + "/metrics.json", m, estimator, estimate_csv);
  const std::string title = std::filesystem::path(estimate_csv).filename().string() + ", " + estimator;
  write_trajectory_svg(out_dir + "/trajectory.svg", title, truth, rows, beacons);
  write_error_svg(out_dir + "/error.svg", title, error_series(truth, rows, eval));
  return m;
}

std::string format_metrics(const Metrics& m) {
  if (m.samples == 0) {
    return "not scored: no pose had ground truth at its stamp (" + std::to_string(m.samples_without_truth) +
           " without, " + std::to_string(m.samples_before_scoring) + " before scoring starts)";
  }
  char line[512];
  std::snprintf(
      line, sizeof line,
      "against ground truth (%zu poses): position RMS %.3f m, mean %.3f m, max %.3f m; heading RMS %s; "
      "E_S mean %s; NEES in 95%% band %.2f",
      m.samples, m.position_rms_m, m.position_mean_m, m.position_max_m,
      m.heading_rms_deg ? (std::to_string(*m.heading_rms_deg).substr(0, 5) + " deg").c_str() : "n/a",
      m.significant_points_mean_m ? (std::to_string(*m.significant_points_mean_m).substr(0, 5) + " m").c_str()
                                  : "n/a",
      m.nees_in_band_fraction);
  return line;
}

}  // namespace beaconloc::cli
