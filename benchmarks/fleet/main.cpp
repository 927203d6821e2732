// Robots served per machine (issue 8, item 3). This process is the localizer: one
// LocalizerParticipant (the code `beaconloc localizer` runs) serving N robots, one estimator per
// robot id. Children on the same machine and domain: a fleet feeder (this program, --role feeder,
// fleet_feeder.cpp) writing the beacon map, 100 Hz odometry and the TOFs of every robot (3
// receivers x 5 Hz slots = 15 TOF/s each), `beaconloc decoder`, and a pose sink (--role sink,
// pose_sink.cpp) standing in for the robots' controllers: it counts the poses that arrive and
// how old they are. With --bare, a bare Fast DDS relay takes the localizer's place (bare_relay.hpp):
// the middleware's own cost of the same samples, the yardstick for the localizer's.
//
// Real time means: the sink gets >= 99 % of the odometry poses of the window (one per odometry
// sample per robot), no odometry increment is lost, and the age of the poses does not grow.
// Prints one table row and, with --csv, appends rows `benchmark,case,metric,value,unit`.
#include <beaconlocPubSubTypes.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "beaconloc/dds/convert.hpp"
#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/topics.hpp"
#include "beaconloc/dds/wall_clock.hpp"
#include "bare_relay.hpp"
#include "bench_support.hpp"
#include "domain_id.hpp"
#include "fleet_feeder.hpp"
#include "localizer_participant.hpp"
#include "offline_run.hpp"
#include "pose_sink.hpp"
#include "process.hpp"
#include "sim/scenario.hpp"

namespace beaconloc::bench {
namespace {

using Clock = std::chrono::steady_clock;

struct LocalizerSample {
  double cpu_s = 0.0;
  std::uint64_t odometry = 0;
  std::uint64_t poses = 0;
};

template <class Served>
LocalizerSample sample(Served& localizer) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  LocalizerSample s;
  s.cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
            static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
  s.odometry = localizer.odometry_processed();
  s.poses = localizer.poses_written();
  return s;
}

struct Run {
  dds::DdsOptions dds;
  std::string self;  // this program, for the children
  int robots = 0;
  double warmup_s = 0.0, window_s = 0.0;
  bool with_sink = true;
  bool bare = false;
  int shards = 1;  // >1: this localizer is one of that many shards (--shard), the others children
  std::string csv;
};

// Runs the children around `localizer` (a LocalizerParticipant, or the BareRelay), measures the
// window, prints.
template <class Served>
int measure(const Run& run, Served& localizer, double rss_empty_mb, double rss_participant_mb) {
  const dds::DdsOptions& dds = run.dds;
  const std::string& self = run.self;
  const int robots = run.robots;
  const double warmup_s = run.warmup_s, window_s = run.window_s;
  const bool with_sink = run.with_sink;

  const double total_s = warmup_s + window_s;
  // With shards, up to 3 s more before the feeder starts: the shards find each other and settle.
  const double shards_wait_s = run.shards > 1 ? 3.0 : 0.0;
  const StampNs window_from_ns = dds::wall_clock_ns() + s_to_ns(warmup_s + 1.0 + shards_wait_s);
  const StampNs window_to_ns = window_from_ns + s_to_ns(window_s);
  const std::string dir = "/tmp/beaconloc-fleet-" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  const std::vector<std::string> dds_args = {"--domain", std::to_string(dds.domain_id),
                                             "--participant-profile", dds.participant_profile};
  auto args = [&](std::vector<std::string> a) {
    a.insert(a.end(), dds_args.begin(), dds_args.end());
    return a;
  };
  std::optional<testing::ChildProcess> sink;
  if (with_sink) {
    sink.emplace(args({self, "--role", "sink", "--from-ns", std::to_string(window_from_ns), "--to-ns",
                       std::to_string(window_to_ns)}),
                 dir + "/sink.log");
  }
  testing::ChildProcess decoder(args({BEACONLOC_EXECUTABLE, "decoder"}), dir + "/decoder.log");
  // The other shards: `beaconloc localizer --shard` with the estimator and receivers of this one.
  std::vector<std::unique_ptr<testing::ChildProcess>> other_shards;
  for (int i = 1; i < run.shards; ++i) {
    other_shards.push_back(std::make_unique<testing::ChildProcess>(
        args({BEACONLOC_EXECUTABLE, "localizer", "--shard", "--estimator", "range_ekf"}),
        dir + "/shard" + std::to_string(i) + ".log"));
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));  // discovery before the first sample
  if constexpr (std::is_same_v<Served, LocalizerParticipant>) {
    if (run.shards > 1) {
      // Every shard known and settled before the first sample: none is handed over in the window.
      const auto end =
          Clock::now() + std::chrono::duration<double>(shards_wait_s) - std::chrono::nanoseconds(kShardSettleNs);
      while (localizer.live_shards() < static_cast<std::size_t>(run.shards) && Clock::now() < end) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      if (localizer.live_shards() < static_cast<std::size_t>(run.shards)) {
        std::fprintf(stderr, "fleet benchmark: %zu of %d shards found in time\n", localizer.live_shards(),
                     run.shards);
        return 1;
      }
      std::this_thread::sleep_for(std::chrono::nanoseconds(kShardSettleNs));
    }
  }
  testing::ChildProcess feeder(args({self, "--role", "feeder", "--robots", std::to_string(robots),
                                     "--seconds", std::to_string(total_s + 1.5)}),
                               dir + "/feeder.log");

  // Window on the localizer's side: from the feeder's start + 1 s + warm-up, as the sink's.
  std::this_thread::sleep_until(Clock::now() +
                                std::chrono::nanoseconds(window_from_ns - dds::wall_clock_ns()));
  const LocalizerSample begin = sample(localizer);
  const double lost_begin = static_cast<double>(localizer.lost_increments());
  double other_shards_cpu_begin = 0.0;
  for (const auto& p : other_shards) other_shards_cpu_begin += process_cpu_s(p->pid());
  const double feeder_cpu_begin = process_cpu_s(feeder.pid()),
               decoder_cpu_begin = process_cpu_s(decoder.pid()),
               sink_cpu_begin = sink ? process_cpu_s(sink->pid()) : 0.0;
  std::vector<double> lag_ms;
  while (dds::wall_clock_ns() < window_to_ns) {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    lag_ms.push_back(ns_to_s(dds::wall_clock_ns() - localizer.newest_odometry_stamp_ns()) * 1e3);
  }
  const LocalizerSample end = sample(localizer);
  const double feeder_cpu = process_cpu_s(feeder.pid()) - feeder_cpu_begin;
  const double decoder_cpu = process_cpu_s(decoder.pid()) - decoder_cpu_begin;
  const double sink_cpu = sink ? process_cpu_s(sink->pid()) - sink_cpu_begin : 0.0;
  double other_shards_cpu = -other_shards_cpu_begin;
  for (const auto& p : other_shards) other_shards_cpu += process_cpu_s(p->pid());
  std::size_t robots_served = static_cast<std::size_t>(robots);
  if constexpr (std::is_same_v<Served, LocalizerParticipant>) robots_served = localizer.robots_served();
  const double lost = static_cast<double>(localizer.lost_increments()) - lost_begin;
  const double rss_mb = resident_mb(getpid());
  const auto feeder_exit = feeder.wait(std::chrono::seconds(30));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last poses reach the sink
  if (sink) sink->signal(SIGINT);
  decoder.signal(SIGINT);
  for (auto& p : other_shards) p->signal(SIGINT);
  const auto sink_exit = sink ? sink->wait(std::chrono::seconds(10)) : std::optional<int>(0);
  decoder.wait(std::chrono::seconds(10));
  for (auto& p : other_shards) p->wait(std::chrono::seconds(10));
  const std::string sink_log = sink ? sink->log() : std::string();
  auto field = [&](const std::string& key) { return log_field(sink_log, key); };
  const double expected_poses = robots * 100.0 * window_s;
  const double taken_ratio = static_cast<double>(end.odometry - begin.odometry) / expected_poses;
  const double pose_ratio = field("poses") / expected_poses;
  const double lag_growth_ms = lag_ms.empty() ? 0.0 : lag_ms.back() - lag_ms.front();
  // Without a sink, what the localizer took and wrote stands for what a reader would get.
  const bool delivered = sink ? pose_ratio >= 0.99 && field("age_p99_ms") < 100.0 : taken_ratio >= 0.99;
  const bool real_time =
      feeder_exit == 0 && sink_exit == 0 && delivered && lost == 0.0 && lag_growth_ms < 50.0;

  const double cpu_pct = 100.0 * (end.cpu_s - begin.cpu_s) / window_s;
  Results r(std::string(run.bare ? "fleet_bare_dds" : "fleet") + (with_sink ? "" : "_no_sink") +
                (run.shards > 1 ? "_shards=" + std::to_string(run.shards) : ""),
            "robots=" + std::to_string(robots));
  r.add("robots", robots, "count");
  r.add("localizer_cpu", cpu_pct, "%core");
  r.add("localizer_cpu_per_robot", cpu_pct / robots, "%core");
  if (run.shards > 1) {
    // This shard receives every robot's samples and serves its share.
    r.add("robots_served", static_cast<double>(robots_served), "count");
    r.add("localizer_cpu_per_robot_served", robots_served ? cpu_pct / static_cast<double>(robots_served) : 0.0,
          "%core");
    r.add("other_shards_cpu", 100.0 * other_shards_cpu / window_s, "%core");
  }
  r.add("localizer_rss", rss_mb, "MB");
  r.add("localizer_rss_per_robot", (rss_mb - rss_participant_mb) * 1024.0 / robots, "kB");
  r.add("localizer_rss_without_robots", rss_participant_mb, "MB");
  r.add("process_rss_before_dds", rss_empty_mb, "MB");
  r.add("odometry_taken_ratio", taken_ratio, "ratio");
  r.add("poses_written_per_s", static_cast<double>(end.poses - begin.poses) / window_s, "1/s");
  r.add("odometry_poses_received_ratio", pose_ratio, "ratio");
  r.add("corrections_received", field("corrections"), "count");
  r.add("lost_increments", lost, "count");
  r.add("pose_age_p50", field("age_p50_ms"), "ms");
  r.add("pose_age_p99", field("age_p99_ms"), "ms");
  r.add("pose_age_max", field("age_max_ms"), "ms");
  r.add("odometry_lag_growth", lag_growth_ms, "ms");
  r.add("feeder_cpu", 100.0 * feeder_cpu / window_s, "%core");
  r.add("feeder_late_max", log_field(feeder.log(), "late_ms"), "ms");
  r.add("decoder_cpu", 100.0 * decoder_cpu / window_s, "%core");
  r.add("sink_cpu", 100.0 * sink_cpu / window_s, "%core");
  r.add("real_time", real_time ? 1.0 : 0.0, "bool");
  r.print();
  if (!run.csv.empty()) r.append_csv(run.csv);
  if (real_time)
    std::filesystem::remove_all(dir);
  else
    std::printf("logs kept in %s\n", dir.c_str());
  return 0;
}

// The localizer role: the localizer (or, bare, the relay standing for it) and the window.
int run_localizer(const Run& run) {
  const double rss_empty_mb = resident_mb(getpid());
  if (run.bare) {
    BareRelay relay(run.dds);
    return measure(run, relay, rss_empty_mb, resident_mb(getpid()));
  }
  const sim::Scenario scenario = sim::default_scenario();
  EstimatorConfig config;
  config.receivers = scenario.receivers;
  LocalizerParticipantOptions options;
  options.shard = run.shards > 1;
  LocalizerParticipant localizer(run.dds, LocalizerCore("range_ekf", config), options);
  return measure(run, localizer, rss_empty_mb, resident_mb(getpid()));
}

}  // namespace
}  // namespace beaconloc::bench

int main(int argc, char** argv) {
  CLI::App app{"beaconloc fleet benchmark: one localizer process serving N robots in real time"};
  std::string role = "localizer", csv;
  int robots = 100;
  double warmup_s = 5.0, window_s = 15.0, seconds = 10.0;
  long long from_ns = 0, to_ns = 0;
  bool no_sink = false, bare = false;
  int shards = 1;
  beaconloc::dds::DdsOptions dds;
  dds.domain_id = 0;
  app.add_option("--role", role, "localizer (default; runs the others), feeder or sink")
      ->check(CLI::IsMember({"localizer", "feeder", "sink"}));
  app.add_option("--robots", robots, "robots served")->check(CLI::PositiveNumber);
  app.add_option("--warmup-s", warmup_s, "seconds before the window (robots find their first fix)");
  app.add_option("--window-s", window_s, "seconds measured");
  app.add_option("--seconds", seconds, "feeder: seconds of samples");
  app.add_option("--from-ns", from_ns, "sink: window start (pose stamps)");
  app.add_option("--to-ns", to_ns, "sink: window end (pose stamps)");
  app.add_option("--domain", dds.domain_id, "DDS domain id (default: one no other run on this machine holds)")
      ->check(CLI::Range(1, 232));
  app.add_option("--participant-profile", dds.participant_profile,
                 "loopback profile (beaconloc.loopback: SHM)");
  app.add_option("--csv", csv, "append rows benchmark,case,metric,value,unit");
  app.add_flag("--no-sink", no_sink,
               "no pose reader on this machine (the robots read their poses elsewhere): the localizer's "
               "own counts tell real time");
  app.add_flag("--bare", bare,
               "a bare Fast DDS relay in the localizer's place (bare_relay.hpp): the same samples in and "
               "out, no estimator; the middleware's own cost of these rates");
  app.add_option("--shards", shards,
                 "this localizer as one of K shards (--shard), the K-1 others `beaconloc localizer --shard` "
                 "children: its CPU per robot it serves, receiving every robot's samples")
      ->check(CLI::Range(1, 16));
  CLI11_PARSE(app, argc, argv);
  if (bare && shards > 1) {
    std::fprintf(stderr, "fleet benchmark: --bare has no shards\n");
    return 2;
  }
  std::optional<beaconloc::testing::DomainLease> lease;
  if (dds.domain_id == 0) dds.domain_id = lease.emplace().id();
  try {
    beaconloc::dds::load_qos_profiles(role == "feeder" ? std::vector<std::string>{BEACONLOC_FLEET_FEEDER_QOS}
                                                       : std::vector<std::string>{});
    if (role == "feeder") return beaconloc::bench::run_feeder(dds, robots, seconds);
    if (role == "sink") return beaconloc::bench::run_sink(dds, from_ns, to_ns);
    return beaconloc::bench::run_localizer(
        {dds, beaconloc::bench::self_executable(), robots, warmup_s, window_s, !no_sink, bare, shards, csv});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fleet benchmark: %s\n", e.what());
    return 2;
  }
}
