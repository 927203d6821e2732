// End-to-end latency of the beaconloc pipeline next to the raw Fast DDS hop (issue 8, item 2):
// the options, the runs (transports interleaved, --repeat times), the table and the CSV rows.
//
// For each transport (shared memory: profile beaconloc.loopback; UDP on 127.0.0.1:
// beaconloc.loopback_udp), in one run:
//  (a) pipeline latency (pipeline_latency.cpp): this process plays the gateway (the built-in
//      simulated scenario at real rates: 100 Hz odometry, one beacon slot every 200 ms heard by the
//      robot's three receivers, paced by the wall clock) and reads beaconloc/pose_estimate;
//      `beaconloc decoder` and `beaconloc localizer` run as child processes. Latency of a slot =
//      steady_clock just before the write of the slot's first RawTof -> steady_clock at the arrival
//      here of the first PoseEstimate after it whose beacons_used holds that beacon (within
//      --match-window-ms). Three DDS hops: gateway -> decoder (raw_tof), decoder -> localizer
//      (beacon_range), localizer -> this process (pose_estimate). Only the first TOF of each slot
//      in the measured window (after --warmup-s, for --duration-s) is timed.
//  (b) raw hop (raw_hop.cpp): this process and a copy of itself (--role echo) ping-pong a RawTof
//      (the same type, robot id and so serialized size as (a)'s TOFs) on topics with raw_tof's QoS
//      profiles; hop = round trip / 2. Twice: paced, one round trip every --hop-period-ms (10 ms
//      by default: the pipeline's 100 Hz cadence) for --hop-duration-s after 1 s not measured,
//      the primary divisor; then back-to-back (the next ping at the pong) for --b2b-hop-s, for
//      reference.
// Both intervals are taken by this process's steady_clock, so no clock is shared across processes.
// Reported per transport: n, p50, p99 and max (nearest rank) of the pipeline latency, of the
// paced hop and of the back-to-back hop; ratio = pipeline / (3 x paced hop) and, for reference,
// pipeline / (3 x back-to-back hop), each at p50 and at p99; the fraction of timed TOFs matched to
// a pose, and the fraction of matches that were correction poses (a pose written at once after a
// range changed the estimate: it repeats the previous pose's stamp) rather than the next
// odometry-driven pose. With --repeat > 1, each figure's median over the runs too.
//
// DDS domains: --domain d runs the pipeline on d and the raw hop on d + 1; without it, two
// domains are leased (testing::DomainLease) for the whole run.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "beaconloc/dds/stop_signal.hpp"
#include "bench_support.hpp"
#include "child.hpp"
#include "common.hpp"
#include "domain_id.hpp"
#include "figures.hpp"
#include "pipeline_latency.hpp"
#include "raw_hop.hpp"

namespace beaconloc::latency {
namespace {

int main_impl(int argc, char** argv) {
  Settings st;
  st.cli = BEACONLOC_CLI_PATH;
  int domain = -1;
  std::string transport = "both";
  std::string role = "bench";
  std::string echo_profile, echo_keystore;
  std::string security = "plain";
  std::string csv_file;
  CLI::App app{
      "End-to-end latency: RawTof -> PoseEstimate through beaconloc decoder and localizer processes, next to "
      "the raw Fast DDS hop (ping-pong) measured in the same run"};
  app.add_option("--transport", transport, "shm, udp or both")->check(CLI::IsMember({"shm", "udp", "both"}));
  app.add_option("--duration-s", st.duration_s, "measured seconds of the pipeline, per transport")
      ->check(CLI::PositiveNumber);
  app.add_option("--warmup-s", st.warmup_s, "seconds of the pipeline not measured first")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--hop-duration-s", st.hop_duration_s, "measured seconds of ping-pong, per transport")
      ->check(CLI::PositiveNumber);
  app.add_option("--hop-period-ms", st.hop_period_ms, "one round trip every this many ms")
      ->check(CLI::PositiveNumber);
  app.add_option("--b2b-hop-s", st.b2b_hop_s,
                 "then seconds of back-to-back ping-pong (next ping at the pong), for reference; 0: none")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--match-window-ms", st.match_window_ms, "a TOF's pose must arrive within this")
      ->check(CLI::PositiveNumber);
  const auto* domain_option =
      app.add_option("--domain", domain,
                     "DDS domain of the pipeline; the ping-pong uses the next one (default: two domains "
                     "leased from those no other run on this machine holds)")
          ->check(CLI::Range(0, 231));
  app.add_option("--estimator", st.estimator, "the localizer's estimator");
  app.add_option("--seed", st.seed, "simulation seed");
  app.add_option("--beaconloc", st.cli, "the beaconloc executable (decoder and localizer)")
      ->check(CLI::ExistingFile);
  app.add_option("--log-dir", st.log_dir, "child process logs (default: a new /tmp/beaconloc-latency-* dir)");
  int repeat = 1;
  app.add_option("--repeat", repeat, "runs (transports interleaved); with more than one, the medians too")
      ->check(CLI::Range(1, 100));
  app.add_option("--csv", csv_file, "append rows benchmark,transport,metric,value,unit to this file");
  app.add_option("--role", role, "internal: bench or echo")->check(CLI::IsMember({"bench", "echo"}));
  app.add_option("--profile", echo_profile, "internal: the echo's participant profile");
  app.add_option("--keystore", echo_keystore, "internal: the echo's keystore (DDS Security)");
  app.add_option("--security", security,
                 "plain, secured (DDS Security: a keystore made by scripts/deployment-keys.sh in the log "
                 "directory) or both, interleaved")
      ->check(CLI::IsMember({"plain", "secured", "both"}));
  CLI11_PARSE(app, argc, argv);
  dds::install_stop_handlers();

  if (role == "echo") return run_echo(domain, echo_profile, echo_keystore);

  // Held until the end: no other run on this machine gets these domains meanwhile.
  std::optional<testing::DomainLease> pipeline_lease, hop_lease;
  if (domain_option->count()) {
    st.pipeline_domain = domain;
    st.hop_domain = domain + 1;
  } else {
    pipeline_lease.emplace();
    hop_lease.emplace();
    st.pipeline_domain = pipeline_lease->id();
    st.hop_domain = hop_lease->id();
  }
  st.self = bench::self_executable();
  if (st.log_dir.empty()) {
    char dir[] = "/tmp/beaconloc-latency-XXXXXX";
    if (!::mkdtemp(dir)) throw std::runtime_error("cannot create a log directory");
    st.log_dir = dir;
  } else {
    std::filesystem::create_directories(st.log_dir);
  }
  std::string keystore;
  if (security != "plain") {
    keystore = st.log_dir + "/keystore";
    const std::string make = "bash " BEACONLOC_SOURCE_DIR "/scripts/deployment-keys.sh deployment " + keystore +
                             " " + kRobotId + " >/dev/null && bash " BEACONLOC_SOURCE_DIR
                             "/scripts/deployment-keys.sh enclave " + keystore + " bench --enclave " +
                             kBenchEnclave + " >/dev/null";
    if (std::system(make.c_str()) != 0) throw std::runtime_error("cannot make the keystore: " + make);
  }
  std::vector<Transport> transports;
  for (const bool secured : {false, true}) {
    if (secured ? security == "plain" : security == "secured") continue;
    const std::string suffix = secured ? "+sec" : "";
    const std::string ks = secured ? keystore : "";
    if (transport != "udp") transports.push_back({"shm" + suffix, "beaconloc.loopback", ks});
    if (transport != "shm") transports.push_back({"udp" + suffix, "beaconloc.loopback_udp", ks});
  }

  // The suite's layout (bench::Results: benchmark,case,metric,value,unit; here the case is the
  // transport), its header written when the file is new. Fail now rather than after the runs.
  if (!csv_file.empty() && !std::ofstream(csv_file, std::ios::app)) {
    throw std::runtime_error("cannot append to " + csv_file);
  }
  const std::string domains =
      st.hop_domain == st.pipeline_domain + 1
          ? std::to_string(st.pipeline_domain) + "-" + std::to_string(st.hop_domain)
          : std::to_string(st.pipeline_domain) + " and " + std::to_string(st.hop_domain);
  std::printf(
      "beaconloc latency: %s, estimator %s, %.0f s measured after %.0f s warm-up; raw hop %.0f s at one "
      "round "
      "trip per %.1f ms (then %.0f s back-to-back); latency divided by %d hops (raw_tof, beacon_range, "
      "pose_estimate); domains %s; logs in "
      "%s\n",
      st.cli.c_str(), st.estimator.c_str(), st.duration_s, st.warmup_s, st.hop_duration_s, st.hop_period_ms,
      st.b2b_hop_s, kPipelineHops, domains.c_str(), st.log_dir.c_str());
  std::fflush(stdout);
  std::vector<std::vector<Figures>> runs(transports.size());
  for (int k = 1; k <= repeat; ++k) {
    for (std::size_t i = 0; i < transports.size(); ++i) {  // interleaved: drift hits both alike
      const auto& t = transports[i];
      std::printf("run %d/%d, %s: pipeline (profile %s)...\n", k, repeat, t.name.c_str(), t.profile.c_str());
      std::fflush(stdout);
      const PipelineResult pipeline = run_pipeline(st, t);
      std::printf("run %d/%d, %s: raw hop...\n", k, repeat, t.name.c_str());
      std::fflush(stdout);
      const HopResult hop = run_hop(st, t);
      runs[i].push_back(figures_of(pipeline, hop));
      print_header("run " + std::to_string(k) + " of " + std::to_string(repeat));
      print_figures(t.name, runs[i].back());
      if (!csv_file.empty()) {
        append_csv(csv_file, repeat > 1 ? "e2e_latency.run" + std::to_string(k) : "e2e_latency", t.name,
                   runs[i].back());
      }
    }
  }
  if (repeat > 1) {
    print_header("median over " + std::to_string(repeat) + " runs (each figure on its own)");
    for (std::size_t i = 0; i < transports.size(); ++i) {
      const Figures m = median_of(runs[i]);
      print_figures(transports[i].name, m);
      if (!csv_file.empty()) append_csv(csv_file, "e2e_latency", transports[i].name, m);
    }
  }
  return 0;
}

}  // namespace
}  // namespace beaconloc::latency

int main(int argc, char** argv) {
  // A child started through this executable (child.hpp): exec it, SIGTERM when we die.
  if (argc > 1 && std::string(argv[1]) == beaconloc::latency::kExecChildOf) {
    return beaconloc::latency::exec_child_of(argc, argv);
  }
  try {
    return beaconloc::latency::main_impl(argc, argv);
  } catch (const beaconloc::latency::Stopped&) {
    std::fprintf(stderr, "latency: stopped\n");
    return 130;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "latency: error: %s\n", e.what());
    return 1;
  }
}
