// Memory and start-up of each participant process (issue 8, item 4). Each run starts a simulated
// gateway (real time), the decoder and the ROS 2 bridge as `beaconloc` processes, then, a second
// later, the localizer, and times from the localizer's start (fork) to the first pose this
// process receives: process start, DDS discovery, the beacon map (transient local), the first
// ranges and the global fix. After `--settle-s` of steady running it reads each process's
// resident memory (VmRSS) and its peak (VmHWM) from /proc. Prints one row per run and the median
// over the runs; with --csv, appends the medians as rows `benchmark,case,metric,value,unit`.
#include <beaconlocPubSubTypes.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "beaconloc/dds/participant.hpp"
#include "beaconloc/dds/topics.hpp"
#include "bench_support.hpp"
#include "domain_id.hpp"
#include "process.hpp"

namespace beaconloc::bench {
namespace {

using Clock = std::chrono::steady_clock;

struct Run {
  double first_pose_s = 0.0;
  std::map<std::string, double> rss_mb, peak_mb;
};

Run run_once(const dds::DdsOptions& dds, double settle_s, const std::string& dir) {
  std::atomic<std::int64_t> first_pose_ns{0};
  dds::Participant participant(dds, "beaconloc.bench.footprint");
  dds::Reader reader = participant.subscribe<msg::PoseEstimatePubSubType>(dds::kPoseEstimateTopic, [&](const msg::PoseEstimate&) {
    std::int64_t expected = 0;
    first_pose_ns.compare_exchange_strong(expected, Clock::now().time_since_epoch().count());
  });
  auto command = [&](const std::string& sub, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{
        BEACONLOC_EXECUTABLE,   sub, "--domain", std::to_string(dds.domain_id), "--participant-profile",
        dds.participant_profile};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return argv;
  };
  std::map<std::string, std::unique_ptr<testing::ChildProcess>> processes;
  processes["gateway"] = std::make_unique<testing::ChildProcess>(
      command("gateway", {"--duration-s", std::to_string(settle_s + 10.0)}), dir + "/gateway.log");
  processes["decoder"] = std::make_unique<testing::ChildProcess>(command("decoder"), dir + "/decoder.log");
  processes["bridge"] = std::make_unique<testing::ChildProcess>(command("bridge"), dir + "/bridge.log");
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const auto started = Clock::now();
  processes["localizer"] =
      std::make_unique<testing::ChildProcess>(command("localizer"), dir + "/localizer.log");
  while (first_pose_ns.load() == 0 && Clock::now() - started < std::chrono::seconds(10)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  Run run;
  run.first_pose_s =
      first_pose_ns.load() == 0
          ? std::numeric_limits<double>::quiet_NaN()
          : std::chrono::duration<double>(Clock::duration(first_pose_ns.load()) - started.time_since_epoch())
                .count();
  std::this_thread::sleep_until(started + std::chrono::duration<double>(settle_s));
  for (const auto& [name, p] : processes) {
    run.rss_mb[name] = resident_mb(p->pid());
    run.peak_mb[name] = peak_resident_mb(p->pid());
  }
  for (const auto& [name, p] : processes) p->signal(SIGTERM);
  for (const auto& [name, p] : processes) {
    const auto code = p->wait(std::chrono::seconds(15));
    if (code != 0)
      std::fprintf(stderr, "footprint: %s exited %d (log %s)\n", name.c_str(), code.value_or(-1),
                   dir.c_str());
  }
  return run;
}

int run(const dds::DdsOptions& dds, int runs, double settle_s, const std::string& csv) {
  const std::string dir = "/tmp/beaconloc-footprint-" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  std::vector<Run> all;
  for (int i = 0; i < runs; ++i) {
    all.push_back(run_once(dds, settle_s, dir));
    const Run& r = all.back();
    std::printf("run %d: first pose %.3f s; RSS MB (peak):", i + 1, r.first_pose_s);
    for (const auto& [name, mb] : r.rss_mb)
      std::printf(" %s %.1f (%.1f)", name.c_str(), mb, r.peak_mb.at(name));
    std::printf("\n");
    std::fflush(stdout);
  }
  Results results("footprint", "median_of_" + std::to_string(runs));
  auto median_of = [&](auto get) {
    std::vector<double> v;
    for (const auto& r : all) v.push_back(get(r));
    return median(v);
  };
  results.add("localizer_first_pose", median_of([](const Run& r) { return r.first_pose_s; }), "s");
  results.add("localizer_first_pose_max",
              percentile(
                  [&] {
                    std::vector<double> v;
                    for (const auto& r : all) v.push_back(r.first_pose_s);
                    return v;
                  }(),
                  1.0),
              "s");
  for (const auto& [name, mb] : all.front().rss_mb) {
    const std::string n = name;
    results.add(n + "_rss", median_of([&](const Run& r) { return r.rss_mb.at(n); }), "MB");
    results.add(n + "_rss_peak", median_of([&](const Run& r) { return r.peak_mb.at(n); }), "MB");
  }
  results.print();
  if (!csv.empty()) results.append_csv(csv);
  std::filesystem::remove_all(dir);
  return 0;
}

}  // namespace
}  // namespace beaconloc::bench

int main(int argc, char** argv) {
  CLI::App app{
      "beaconloc footprint benchmark: resident memory of each participant, localizer start to first pose"};
  beaconloc::dds::DdsOptions dds;
  dds.domain_id = 0;
  int runs = 5;
  double settle_s = 10.0;
  std::string csv;
  app.add_option("--runs", runs, "runs (fresh processes each)")->check(CLI::PositiveNumber);
  app.add_option("--settle-s", settle_s, "seconds of running before memory is read")
      ->check(CLI::PositiveNumber);
  app.add_option("--domain", dds.domain_id, "DDS domain id (default: one no other run on this machine holds)")
      ->check(CLI::Range(1, 232));
  app.add_option("--participant-profile", dds.participant_profile,
                 "loopback profile (beaconloc.loopback: SHM)");
  app.add_option("--csv", csv, "append rows benchmark,case,metric,value,unit");
  CLI11_PARSE(app, argc, argv);
  std::optional<beaconloc::testing::DomainLease> lease;
  if (dds.domain_id == 0) dds.domain_id = lease.emplace().id();
  try {
    beaconloc::dds::load_qos_profiles({});
    return beaconloc::bench::run(dds, runs, settle_s, csv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "footprint benchmark: %s\n", e.what());
    return 2;
  }
}
